"""Formulas to BDDs: slugs' section rules, the static variable order, and the translation.

Kept apart from the game operators (symbolic.py), which only see BDDs. Every proposition
``p`` has a current copy ``p`` and a next-step copy ``p'``. Formula trees are walked with an
explicit stack, so formulas may be nested to any depth.
"""

from __future__ import annotations

from ltl_synthesizer.cudd_import import cudd

from respec.errors import quoted
from respec.ltl import And, Const, Formula, Iff, Implies, Next, Not, Or, Var, children, to_infix
from respec.spec import GR1Specification

from ltl_synthesizer.errors import NotGR1FormulaError, UndeclaredPropositionError

INIT_SECTIONS = ('env_init', 'sys_init')


def primed(name: str) -> str:
    """The name of the next-step copy of a proposition."""
    return name + "'"


class Translator:
    """Translates formulas over the declared propositions into BDDs of ``bdd``."""

    def __init__(self, bdd: cudd.BDD, inputs: list[str], outputs: list[str], check=None):
        self.bdd = bdd
        self.outputs = set(outputs)
        self.declared = set(inputs) | self.outputs
        self.check = check or (lambda: None)

    def translate(self, formula: Formula, section: str) -> cudd.Function:
        """The BDD of a formula over current and next-step variables; slugs' rules of the
        section (no next step in initial conditions, no next output in env_trans) apply."""
        self.check()
        if section in INIT_SECTIONS and any(under_next for _, under_next in walk(formula)):
            raise NotGR1FormulaError(
                f'{section}: initial conditions cannot refer to the next step: {to_infix(formula)}',
                item=to_infix(formula))
        if section == 'env_trans':
            bad = next_outputs(formula, self.outputs)
            if bad:
                # slugs rejects this too: the environment moves first and cannot see the system's move.
                raise NotGR1FormulaError(
                    f"env_trans: environment assumption refers to the next value of output '{bad[0]}': "
                    f'{to_infix(formula)}', item=bad[0])
        return self._translate(formula, section)

    def conjunction(self, formulas, section: str) -> cudd.Function:
        result = self.bdd.true
        for formula in formulas:
            result &= self.translate(formula, section)
        return result

    def _translate(self, root: Formula, section: str) -> cudd.Function:
        """Post-order evaluation with an explicit stack of (node, under next, children done)."""
        results = []
        stack = [(root, False, False)]
        while stack:
            formula, under_next, expanded = stack.pop()
            if isinstance(formula, Next) and under_next:
                raise NotGR1FormulaError(f'{section}: nested next is not GR(1): {to_infix(formula)}',
                                          item=to_infix(formula))
            inner = under_next or isinstance(formula, Next)
            if not expanded and children(formula):
                stack.append((formula, under_next, True))
                stack.extend((child, inner, False) for child in reversed(children(formula)))
                continue
            arity = len(children(formula))
            args = results[len(results) - arity:] if arity else []
            del results[len(results) - arity:]
            results.append(self._node(formula, args, under_next, section))
        return results[0]

    def _node(self, formula: Formula, args: list, under_next: bool, section: str) -> cudd.Function:
        bdd = self.bdd
        if isinstance(formula, Const):
            return bdd.true if formula.value else bdd.false
        if isinstance(formula, Var):
            if formula.name not in self.declared:
                raise UndeclaredPropositionError(
                    f"{section}: unknown proposition {quoted(formula.name)} (declare it as an input or output)",
                    item=formula.name)
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


def walk(formula: Formula):
    """Every node of ``formula`` (pre-order) with whether it lies under a next operator."""
    stack = [(formula, False)]
    while stack:
        node, under_next = stack.pop()
        yield node, under_next
        inner = under_next or isinstance(node, Next)
        stack.extend((child, inner) for child in reversed(children(node)))


def next_outputs(formula: Formula, outputs: set[str]) -> list[str]:
    """The outputs whose next value ``formula`` reads, sorted."""
    return sorted({node.name for node, under_next in walk(formula)
                   if under_next and isinstance(node, Var) and node.name in outputs})


def check_declarations(spec: GR1Specification) -> None:
    seen = set()
    for name in list(spec.env_props) + list(spec.sys_props):
        if not isinstance(name, str) or not name or name.endswith("'"):
            raise UndeclaredPropositionError(f'invalid proposition name {name!r}', item=name)
        if name in seen:
            raise UndeclaredPropositionError(f"proposition '{name}' is declared twice", item=name)
        seen.add(name)


def variable_order(spec: GR1Specification, strategy: str) -> list[str]:
    """Static variable order: declared, or 'affinity' (first appearance in the safety formulas).

    Propositions used together (an action's activation and its outcomes) then sit together,
    which keeps the transition relations small.
    """
    declared = list(spec.env_props) + list(spec.sys_props)
    if strategy == 'declared':
        return declared
    if strategy != 'affinity':
        raise ValueError(f'unknown variable order {strategy!r}')
    known = set(declared)
    found = {}  # an ordered set
    for formula in list(spec.sys_trans) + list(spec.env_trans) + list(spec.sys_liveness) \
            + list(spec.env_liveness) + list(spec.env_init) + list(spec.sys_init):
        for node, _ in walk(formula):
            if isinstance(node, Var) and node.name in known:
                found.setdefault(node.name)
    return list(found) + [name for name in declared if name not in found]
