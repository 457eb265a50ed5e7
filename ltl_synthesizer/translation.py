"""Formulas to BDDs: slugs' section rules, the static variable order, and the translation.

Kept apart from the game operators (symbolic.py), which only see BDDs. Every proposition
``p`` has a current copy ``p`` and a next-step copy ``p'``. Formula trees are walked with an
explicit stack, so formulas may be nested to any depth.
"""

from __future__ import annotations

from typing import Callable, Iterable, Sequence

from ltl_synthesizer.cudd_import import Node, cudd

from respec.vocabulary.errors import quoted
from respec.ltl import And, Const, Formula, Iff, Implies, Next, Not, Or, Var, children, to_infix
from respec.spec import GR1Specification

from ltl_synthesizer.errors import NotGR1FormulaError, UndeclaredPropositionError

INIT_SECTIONS = ('env_init', 'sys_init')


def primed(name: str) -> str:
    """The name of the next-step copy of a proposition."""
    return name + "'"


def declare_pair(bdd: cudd.BDD, name: str) -> None:
    """Declare proposition ``name`` and its next-step copy (once), next to each other."""
    if name not in bdd.vars:
        bdd.declare(name, primed(name))
        bdd.group({name: 2})  # reordering keeps each pair adjacent (cheap renaming)


class Translator:
    """Translates formulas over the declared propositions into BDDs of ``bdd``.

    Each proposition's BDD variables are declared (``declare_pair``) when a formula first uses
    it, so translating the formulas in some order places the variables in order of first use.
    """

    def __init__(self, bdd: cudd.BDD, inputs: list[str], outputs: list[str],
                 check: Callable[[], object] | None = None) -> None:
        self.bdd = bdd
        self.outputs = set(outputs)
        self.declared = set(inputs) | self.outputs
        self.check = check or (lambda: None)

    def translate(self, formula: Formula, section: str) -> cudd.Function:
        """The BDD of a formula over current and next-step variables; slugs' rules of the
        section (no next step in initial conditions, no next output in env_trans) apply."""
        self.check()
        return self._translate(formula, section)

    def conjunction(self, formulas: Iterable[Formula], section: str) -> cudd.Function:
        result = self.bdd.true
        for formula in formulas:
            result &= self.translate(formula, section)
        return result

    def _translate(self, root: Formula, section: str) -> cudd.Function:
        """Post-order evaluation with an explicit stack of (node, under next, children done),
        checking the section's rules on the way (one pass over the formula).

        Formulas may share subformulas (slugsin's memory buffers make a DAG smaller than its
        tree): each (subformula, under next) is translated once. Leaves are translated when
        met and children already translated are not pushed: large specifications have
        hundreds of thousands of nodes, and this loop is most of their translation time.
        """
        done: tuple[dict[int, Node], dict[int, Node]] = ({}, {})  # the BDDs of subformulas by id(), outside and under next
        next_outputs: set[str] = set()
        stack = [(root, False, False)]
        pop, push = stack.pop, stack.append
        while stack:
            formula, under_next, expanded = pop()
            translated = done[under_next]
            if id(formula) in translated:
                continue
            kind = formula.__class__
            if kind is Var or kind is Const:
                # A Var (mypy narrows by isinstance, not by the __class__ this hot loop dispatches on):
                if kind is Var and under_next and formula.name in self.outputs:  # type: ignore[attr-defined]
                    next_outputs.add(formula.name)  # type: ignore[attr-defined]
                translated[id(formula)] = self._node(formula, (), under_next, section)
                continue
            inner = under_next or kind is Next
            below = done[inner]
            if expanded:
                translated[id(formula)] = self._node(
                    formula, [below[id(child)] for child in children(formula)], under_next, section)
                continue
            if kind is Next:
                if under_next:
                    raise NotGR1FormulaError(f'{section}: nested next is not GR(1): {to_infix(formula)}',
                                              item=to_infix(formula))
                if section in INIT_SECTIONS:
                    raise NotGR1FormulaError(
                        f'{section}: initial conditions cannot refer to the next step: {to_infix(root)}',
                        item=to_infix(root))
            push((formula, under_next, True))
            for child in reversed(children(formula)):
                if id(child) not in below:
                    push((child, inner, False))
        if section == 'env_trans' and next_outputs:
            # slugs rejects this too: the environment moves first and cannot see the system's move.
            bad = min(next_outputs)
            raise NotGR1FormulaError(
                f"env_trans: environment assumption refers to the next value of output '{bad}': "
                f'{to_infix(root)}', item=bad)
        return done[False][id(root)]

    def _node(self, formula: Formula, args: Sequence[Node], under_next: bool, section: str) -> cudd.Function:
        bdd = self.bdd
        if isinstance(formula, Const):
            return bdd.true if formula.value else bdd.false
        if isinstance(formula, Var):
            if formula.name not in self.declared:
                raise UndeclaredPropositionError(
                    f"{section}: unknown proposition {quoted(formula.name)} (declare it as an input or output)",
                    item=formula.name)
            declare_pair(bdd, formula.name)
            return bdd.var(primed(formula.name) if under_next else formula.name)
        if isinstance(formula, Next):
            return args[0]
        if isinstance(formula, Not):
            return ~args[0]
        if isinstance(formula, And):
            result = bdd.true
            for arg in args:
                result &= arg
            return result
        if isinstance(formula, Or):
            result = bdd.false
            for arg in args:
                result |= arg
            return result
        if isinstance(formula, Implies):
            return ~args[0] | args[1]
        if isinstance(formula, Iff):
            return bdd.apply('<=>', args[0], args[1])
        raise NotGR1FormulaError(f'{section}: not a formula: {formula!r}', item=repr(formula))


def check_declarations(spec: GR1Specification) -> None:
    seen: set[str] = set()
    for name in list(spec.env_props) + list(spec.sys_props):
        if not isinstance(name, str) or not name or name.endswith("'"):
            raise UndeclaredPropositionError(f'invalid proposition name {name!r}', item=name)
        if name in seen:
            raise UndeclaredPropositionError(f"proposition '{name}' is declared twice", item=name)
        seen.add(name)
