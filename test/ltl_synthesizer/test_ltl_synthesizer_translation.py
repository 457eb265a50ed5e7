"""Translation of respec.ltl formulas into BDDs over current and next-step copies."""

import itertools

import pytest

from ltl_synthesizer import NotGR1FormulaError, Options, UndeclaredPropositionError
from ltl_synthesizer.symbolic import SymbolicGame, primed
from respec.ltl import FALSE, TRUE, conj, disj, iff, implies, neg, next_, var
from respec.spec import GR1Specification

a, b, c = var('a'), var('b'), var('c')


def game(options=None, **sections):
    return SymbolicGame(GR1Specification(env_props=['a'], sys_props=['b', 'c'], **sections), options)


def truth_table(g, u, names):
    return [g.evaluate(u, dict(zip(names, values)))
            for values in itertools.product([False, True], repeat=len(names))]


def test_variables_are_interleaved_current_and_next():
    g = game(sys_trans=[implies(b, next_(c))])  # the game alone never reorders
    order = sorted(g.bdd.vars, key=g.bdd.level_of_var)
    # 'affinity' order: propositions in order of first use in the safety formulas.
    assert order == ['b', "b'", 'c', "c'", 'a', "a'"]
    for name in ('a', 'b', 'c'):
        assert g.bdd.level_of_var(primed(name)) == g.bdd.level_of_var(name) + 1


def test_sifting_keeps_each_current_and_next_pair_adjacent():
    g = game(sys_trans=[implies(b, next_(c)), iff(next_(a), conj([b, neg(c)]))])
    g.bdd.reorder()
    for name in ('a', 'b', 'c'):
        assert abs(g.bdd.level_of_var(primed(name)) - g.bdd.level_of_var(name)) == 1


@pytest.mark.parametrize('formula, expected', [
    (conj([a, b]), lambda a, b, c: a and b),
    (disj([a, neg(c)]), lambda a, b, c: a or not c),
    (implies(a, b), lambda a, b, c: (not a) or b),
    (iff(a, conj([b, c])), lambda a, b, c: a == (b and c)),
    (TRUE, lambda a, b, c: True),
    (FALSE, lambda a, b, c: False),
])
def test_boolean_connectives(formula, expected):
    g = game()
    u = g.translator.translate(formula, 'sys_trans')
    names = ['a', 'b', 'c']
    assert truth_table(g, u, names) == [expected(*v) for v in itertools.product([False, True], repeat=3)]


def test_next_maps_to_the_primed_copy_and_distributes():
    g = game()
    u = g.translator.translate(next_(conj([a, neg(b)])), 'sys_trans')
    assert u == g.bdd.var("a'") & ~g.bdd.var("b'")
    assert g.bdd.support(u) == {"a'", "b'"}


def test_priming_twice_is_the_identity():
    g = game()
    u = g.translator.translate(disj([a, conj([b, neg(c)])]), 'sys_trans')
    assert g.bdd.support(g.prime(u)) == {"a'", "b'", "c'"}
    assert g.prime(g.prime(u)) == u


def test_unknown_proposition_is_named():
    with pytest.raises(UndeclaredPropositionError) as raised:
        game(sys_liveness=[var('ghost')])
    assert raised.value.item == 'ghost' and raised.value.code == 'UNKNOWN_PROPOSITION'
    assert "sys_liveness: unknown proposition 'ghost'" in str(raised.value)


def test_nested_next_and_next_in_init_are_rejected():
    with pytest.raises(NotGR1FormulaError) as raised:
        game(sys_trans=[next_(next_(a))])
    assert raised.value.code == 'INVALID_FORMULA' and 'nested next' in str(raised.value)
    with pytest.raises(NotGR1FormulaError) as raised:
        game(sys_init=[next_(b)])
    assert 'initial conditions' in str(raised.value) and raised.value.item == 'next(b)'


def test_environment_cannot_constrain_the_next_output():
    with pytest.raises(NotGR1FormulaError) as raised:
        game(env_trans=[implies(a, next_(b))])
    assert raised.value.item == 'b'


def test_duplicate_declaration_is_named():
    with pytest.raises(UndeclaredPropositionError) as raised:
        SymbolicGame(GR1Specification(env_props=['a'], sys_props=['a']))
    assert raised.value.item == 'a'


def test_enforceable_predecessor():
    # The system copies a' into b'; the environment may only raise a when b holds.
    g = game(env_trans=[implies(neg(b), neg(next_(a)))])
    target = g.translator.translate(iff(next_(b), next_(a)), 'sys_trans')
    assert g.cox(target) == g.true
    # Forcing b' & a' needs the environment's cooperation: never enforceable.
    assert g.cox(g.translator.translate(conj([next_(a), next_(b)]), 'sys_trans')) == g.false
    # Forcing !a' is enforceable exactly where the environment must keep a low.
    assert g.cox(g.translator.translate(neg(next_(a)), 'sys_trans')) == ~g.bdd.var('b')


@pytest.mark.parametrize('cluster_limit', [0, 50, 10**9])
def test_partitioned_product_equals_monolithic(cluster_limit):
    sections = dict(env_trans=[implies(b, next_(a)), implies(c, neg(next_(a)))],
                    sys_trans=[iff(next_(b), a), implies(next_(c), next_(b)), implies(a, next_(c))])
    g = SymbolicGame(GR1Specification(env_props=['a'], sys_props=['b', 'c'], **sections),
                     options=Options(cluster_limit=cluster_limit))
    target = g.translator.translate(disj([next_(c), conj([a, neg(next_(b))])]), 'sys_trans')
    monolithic = ~g.bdd.exist(["a'"], g.env_trans() & ~g.bdd.exist(["b'", "c'"], g.sys_trans() & target))
    assert g.cox(target) == monolithic


def test_the_invariant_stays_out_of_the_products_and_the_operators_stay_exact():
    """sys_trans's formulas over current inputs only form the system's invariant: the
    responses leave it out, and cox, env_cox, sys_trans and legal_moves stay exact, also
    where the environment has no legal move (there the system wins by default)."""
    sections = dict(env_trans=[implies(conj([a, b]), FALSE), iff(next_(a), neg(a))],
                    sys_trans=[neg(conj([a, var('d')])), implies(next_(c), next_(b)),
                               implies(a, next_(c))])
    spec = GR1Specification(env_props=['a', 'd'], sys_props=['b', 'c'], **sections)
    apart, kept_in = (SymbolicGame(spec, options=Options(invariant_apart=flag)) for flag in (True, False))
    assert apart.sys_invariant == apart.translator.translate(neg(conj([a, var('d')])), 'sys_trans')
    assert kept_in.sys_invariant == kept_in.true
    for g in (apart, kept_in):
        env_trans, sys_trans = g.env_trans(), g.sys_trans()
        assert sys_trans == g.translator.conjunction(sections['sys_trans'], 'sys_trans')
        assert g.legal_moves == env_trans & sys_trans
        for target_formula in (next_(c), disj([next_(c), conj([a, neg(next_(b))])]), neg(next_(b))):
            target = g.translator.translate(target_formula, 'sys_trans')
            monolithic = ~g.bdd.exist(["a'", "d'"], env_trans & ~g.bdd.exist(
                ["b'", "c'"], sys_trans & target))
            assert g.cox(target) == monolithic
            escapes = g.bdd.exist(["b'", "c'"], sys_trans & ~target)
            assert g.env_cox(target) == env_trans & ~escapes
    # Where a and b hold the environment has no move: not lost, although a & d breaks sys_trans.
    stuck = apart.bdd.cube({'a': True, 'b': True, 'd': True})
    assert stuck & ~apart.not_lost_at_once == apart.false
    assert apart.cox(apart.false) & stuck == stuck
