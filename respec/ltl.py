"""LTL formulas for the GR(1) fragment, as immutable trees with slugs printers.

Every formula the project builds or parses is one of these nodes; text is only made by the
printers here, so the infix (``.structuredslugs``) and prefix (``.slugsin``) syntaxes live
in one place.

    >>> f = implies(var('a'), next_(neg(var('b'))))
    >>> to_infix(f)
    'a -> next(!b)'
    >>> to_prefix(f)
    "| ! a ! b'"
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterable, Mapping


@dataclass(frozen=True, slots=True)
class Formula:
    """Base class of all formula nodes (immutable, hashable, ordered by printing; slotted:
    large specifications hold millions of nodes)."""


@dataclass(frozen=True, slots=True)
class Const(Formula):
    value: bool


@dataclass(frozen=True, slots=True)
class Var(Formula):
    name: str


@dataclass(frozen=True, slots=True)
class Not(Formula):
    arg: Formula


@dataclass(frozen=True, slots=True)
class And(Formula):
    args: tuple[Formula, ...]


@dataclass(frozen=True, slots=True)
class Or(Formula):
    args: tuple[Formula, ...]


@dataclass(frozen=True, slots=True)
class Implies(Formula):
    left: Formula
    right: Formula


@dataclass(frozen=True, slots=True)
class Iff(Formula):
    left: Formula
    right: Formula


@dataclass(frozen=True, slots=True)
class Next(Formula):
    """The value of ``arg`` in the next time step (LTL's "next" operator, ◯)."""

    arg: Formula


TRUE = Const(True)
FALSE = Const(False)

# The constructors below make nodes without the dataclass __init__, which (frozen) sets each
# field through object.__setattr__: allocating the node and calling its slots' setters costs
# half as much, and large specifications build millions of nodes. The nodes are the same.
FIELD_SETTERS: dict[type[Formula], dict[str, Callable[[Formula, Any], None]]] = {kind: {name: getattr(kind, name).__set__ for name in kind.__dataclass_fields__}
                 for kind in (Const, Var, Not, And, Or, Implies, Iff, Next)}
_new = object.__new__
_set_name = FIELD_SETTERS[Var]['name']
_set_not_arg, _set_next_arg = FIELD_SETTERS[Not]['arg'], FIELD_SETTERS[Next]['arg']
_set_args = {And: FIELD_SETTERS[And]['args'], Or: FIELD_SETTERS[Or]['args']}
_set_sides = {kind: (FIELD_SETTERS[kind]['left'], FIELD_SETTERS[kind]['right']) for kind in (Implies, Iff)}


def var(name: str) -> Var:
    node = _new(Var)
    _set_name(node, name)
    return node


def neg(arg: Formula) -> Formula:
    """Negation; folds constants and double negation."""
    if isinstance(arg, Const):
        return FALSE if arg.value else TRUE
    if isinstance(arg, Not):
        return arg.arg
    node = _new(Not)
    _set_not_arg(node, arg)
    return node


def conj(args: Iterable[Formula]) -> Formula:
    """Conjunction of any number of formulas (TRUE when empty; flattens nested ands)."""
    return _associative(And, args, unit=TRUE, zero=FALSE)


def disj(args: Iterable[Formula]) -> Formula:
    """Disjunction of any number of formulas (FALSE when empty; flattens nested ors)."""
    return _associative(Or, args, unit=FALSE, zero=TRUE)


def implies(left: Formula, right: Formula) -> Formula:
    return _binary(Implies, left, right)


def iff(left: Formula, right: Formula) -> Formula:
    return _binary(Iff, left, right)


def next_(arg: Formula) -> Formula:
    node = _new(Next)
    _set_next_arg(node, arg)
    return node


def _binary(kind: type[Implies] | type[Iff], left: Formula, right: Formula) -> Formula:
    node: Formula = _new(kind)
    set_left, set_right = _set_sides[kind]
    set_left(node, left)
    set_right(node, right)
    return node


def _associative(kind: type[And] | type[Or], args: Iterable[Formula], unit: Const, zero: Const) -> Formula:
    flat: list[Formula] = []
    for arg in args:
        if isinstance(arg, Const):  # the unit or the zero
            if arg.value == zero.value:
                return zero
            continue
        if isinstance(arg, kind):
            flat.extend(arg.args)
        else:
            flat.append(arg)
    if not flat:
        return unit
    if len(flat) == 1:
        return flat[0]
    node: Formula = _new(kind)
    _set_args[kind](node, tuple(flat))
    return node


# --- printers ---------------------------------------------------------------------------

# Binding strength in structured slugs, tightest first; used to print minimal parentheses.
_PRECEDENCE = {Const: 6, Var: 6, Next: 6, Not: 5, And: 4, Or: 3, Implies: 2, Iff: 1}


def to_infix(formula: Formula) -> str:
    """Print in structured-slugs infix syntax (``!``, ``&``, ``|``, ``->``, ``<->``, ``next()``)."""
    if isinstance(formula, Const):
        return 'TRUE' if formula.value else 'FALSE'
    if isinstance(formula, Var):
        return formula.name
    if isinstance(formula, Next):
        return f'next({to_infix(formula.arg)})'
    if isinstance(formula, Not):
        return '!' + _infix_operand(formula.arg, Not, strict=False)
    if isinstance(formula, (And, Or)):
        symbol = ' & ' if isinstance(formula, And) else ' | '
        return symbol.join(_infix_operand(arg, type(formula), strict=True) for arg in formula.args)
    if isinstance(formula, (Implies, Iff)):
        symbol = ' -> ' if isinstance(formula, Implies) else ' <-> '
        # Both operators are printed non-associatively: nested ones always get parentheses.
        return (_infix_operand(formula.left, type(formula), strict=True) + symbol
                + _infix_operand(formula.right, type(formula), strict=True))
    raise TypeError(f'not a formula: {formula!r}')


def _infix_operand(operand: Formula, parent: type, strict: bool) -> str:
    text = to_infix(operand)
    mine, theirs = _PRECEDENCE[type(operand)], _PRECEDENCE[parent]
    needs_parentheses = mine <= theirs if strict else mine < theirs
    return f'({text})' if needs_parentheses else text


def to_prefix(formula: Formula) -> str:
    """Print in slugsin prefix syntax: ``! a``, ``& a b``, ``| a b``, ``^ a b``, ``a'``.

    slugsin primes variables only, so ``next`` is pushed down to the variables.
    """
    return ' '.join(_prefix_tokens(formula, primed=False))


def _prefix_tokens(formula: Formula, primed: bool) -> list[str]:
    if isinstance(formula, Const):
        return ['1' if formula.value else '0']
    if isinstance(formula, Var):
        return [formula.name + ("'" if primed else '')]
    if isinstance(formula, Next):
        if primed:
            raise ValueError(f'nested next is not GR(1): {to_infix(formula)}')
        return _prefix_tokens(formula.arg, primed=True)
    if isinstance(formula, Not):
        return ['!'] + _prefix_tokens(formula.arg, primed)
    if isinstance(formula, (And, Or)):
        operator = '&' if isinstance(formula, And) else '|'
        tokens = _prefix_tokens(formula.args[-1], primed)
        for arg in reversed(formula.args[:-1]):
            tokens = [operator] + _prefix_tokens(arg, primed) + tokens
        return tokens
    if isinstance(formula, Implies):
        return ['|', '!'] + _prefix_tokens(formula.left, primed) + _prefix_tokens(formula.right, primed)
    if isinstance(formula, Iff):
        return ['!', '^'] + _prefix_tokens(formula.left, primed) + _prefix_tokens(formula.right, primed)
    raise TypeError(f'not a formula: {formula!r}')


def variables(formula: Formula) -> set[str]:
    """Names of all variables in the formula, whether current or next step."""
    if isinstance(formula, Var):
        return {formula.name}
    if isinstance(formula, Const):
        return set()
    return set().union(*(variables(child) for child in children(formula)))


def children(formula: Formula) -> tuple[Formula, ...]:
    if isinstance(formula, (Not, Next)):
        return (formula.arg,)
    if isinstance(formula, (And, Or)):
        return formula.args
    if isinstance(formula, (Implies, Iff)):
        return (formula.left, formula.right)
    return ()


def mentions_next(formula: Formula) -> bool:
    """True if the formula refers to the next time step anywhere."""
    return isinstance(formula, Next) or any(mentions_next(c) for c in children(formula))


def evaluate(formula: Formula, current: dict[str, bool], next_step: dict[str, bool] | None = None) -> bool:
    """Truth value of ``formula`` on a step from valuation ``current`` to ``next_step``.

    Variables under ``next`` are read from ``next_step``; a missing variable raises KeyError.
    """
    if isinstance(formula, Const):
        return formula.value
    if isinstance(formula, Var):
        return current[formula.name]
    if isinstance(formula, Next):
        if next_step is None:
            raise ValueError(f'{to_infix(formula)} needs the next step')
        return evaluate(formula.arg, next_step, None)
    if isinstance(formula, Not):
        return not evaluate(formula.arg, current, next_step)
    if isinstance(formula, And):
        return all(evaluate(arg, current, next_step) for arg in formula.args)
    if isinstance(formula, Or):
        return any(evaluate(arg, current, next_step) for arg in formula.args)
    if isinstance(formula, Implies):
        return (not evaluate(formula.left, current, next_step)) or evaluate(formula.right, current, next_step)
    if isinstance(formula, Iff):
        return evaluate(formula.left, current, next_step) == evaluate(formula.right, current, next_step)
    raise TypeError(f'not a formula: {formula!r}')


def partial_evaluate(formula: Formula, current: Mapping[str, bool], next_step: Mapping[str, bool]) -> bool | None:
    """Kleene truth value of ``formula`` on a step: True, False, or None if it depends on
    variables missing from the valuations (strong Kleene logic, so partial assignments can
    already refute a formula)."""
    if isinstance(formula, Const):
        return formula.value
    if isinstance(formula, Var):
        return current.get(formula.name)
    if isinstance(formula, Next):
        return partial_evaluate(formula.arg, next_step, {})
    if isinstance(formula, Not):
        value = partial_evaluate(formula.arg, current, next_step)
        return None if value is None else not value
    if isinstance(formula, (And, Or)):
        absorbing = isinstance(formula, Or)  # True absorbs a disjunction, False a conjunction
        unknown = False
        for arg in formula.args:
            value = partial_evaluate(arg, current, next_step)
            if value is absorbing:
                return absorbing
            unknown |= value is None
        return None if unknown else not absorbing
    if isinstance(formula, Implies):
        return partial_evaluate(Or((Not(formula.left), formula.right)), current, next_step)
    if isinstance(formula, Iff):
        left = partial_evaluate(formula.left, current, next_step)
        right = partial_evaluate(formula.right, current, next_step)
        return None if left is None or right is None else left == right
    raise TypeError(f'not a formula: {formula!r}')
