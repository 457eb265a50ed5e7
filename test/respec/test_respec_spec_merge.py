"""Merging GR(1) sub-specifications: first appearance wins, duplicates dropped, stable order."""

import pytest

from respec.ltl import neg, next_, var
from respec.spec import GR1Specification, PropositionConflictError, merge_specifications

A, B, C = var('a'), var('b'), var('c')


def test_merge_keeps_first_appearance_and_drops_duplicates():
    first = GR1Specification(env_props=['a'], sys_props=['b'], sys_trans=[B, neg(A)], env_liveness=[A])
    second = GR1Specification(env_props=['c', 'a'], sys_props=['b'], sys_trans=[neg(A), next_(B)],
                              env_liveness=[A, C])
    merged = merge_specifications([first, second])
    assert merged.env_props == ['a', 'c']
    assert merged.sys_props == ['b']
    assert merged.sys_trans == [B, neg(A), next_(B)]
    assert merged.env_liveness == [A, C]
    # The inputs are not modified.
    assert first.sys_trans == [B, neg(A)]


def test_merge_is_order_sensitive_but_deterministic():
    x = GR1Specification(sys_props=['p', 'q'], sys_init=[neg(var('p'))])
    y = GR1Specification(sys_props=['r', 'p'], sys_init=[neg(var('r'))])
    assert x.merge(y).sys_props == ['p', 'q', 'r']
    assert y.merge(x).sys_props == ['r', 'p', 'q']
    assert x.merge(y).to_structuredslugs() == x.merge(y).to_structuredslugs()


def test_shared_precondition_formula_appears_once():
    formula = neg(var('template_c'))
    merged = merge_specifications([GR1Specification(sys_trans=[formula])] * 3)
    assert merged.sys_trans == [formula]


def test_conflicting_proposition_kinds():
    with pytest.raises(PropositionConflictError) as caught:
        merge_specifications([GR1Specification(env_props=['x']), GR1Specification(sys_props=['x'])])
    assert caught.value.item == 'x'


def test_proposition_sets_and_helpers():
    spec = GR1Specification(env_props=['e'], sys_props=['s'], sys_trans=[var('s'), var('ghost')],
                            env_init=[neg(var('e'))])
    assert spec.env_prop_set == frozenset({'e'}) and spec.sys_prop_set == frozenset({'s'})
    assert spec.propositions() == ['e', 's']
    assert spec.formulas() == [neg(var('e')), var('s'), var('ghost')]
    assert spec.undeclared_variables() == ['ghost']


def test_merge_of_nothing_is_empty():
    assert merge_specifications([]) == GR1Specification()
