"""Structured slugs' integer variables (``level: 3...107`` in [INPUT] / [OUTPUT]), bit-blasted
as slugs' compiler does.

Bits ``level@0.3.107``, ``level@1``, ... hold ``value - low``; each comparison
(``= != < <= > >=`` over sums with ``+``) is expanded over the values involved; range limits
are added to the owner's init and transition sections (by respec.parsing.specifications).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Callable

from respec.ltl import TRUE, Formula, conj, disj, neg, next_, var

COMPARATORS: dict[str, Callable[[int, int], bool]] = {
    '=': lambda a, b: a == b, '!=': lambda a, b: a != b, '<': lambda a, b: a < b,
    '<=': lambda a, b: a <= b, '>': lambda a, b: a > b, '>=': lambda a, b: a >= b,
}
_MAX_EXPANSION = 1 << 16   # valuations enumerated to expand one integer comparison


@dataclass(frozen=True)
class IntegerVariable:
    """A structured-slugs integer ``name: low...high``, stored as slugs stores it: the bits of
    ``value - low``, least significant first, named ``name@0.low.high``, ``name@1``, ..."""

    name: str
    low: int
    high: int

    @property
    def bits(self) -> list[str]:
        count = 0
        while 2 ** count <= self.high - self.low:
            count += 1
        return [f'{self.name}@0.{self.low}.{self.high}' if k == 0 else f'{self.name}@{k}' for k in range(count)]

    def equals(self, value: int, next_step: bool) -> Formula:
        """The bits spelling ``value`` (which must lie in the range)."""
        offset = value - self.low
        literals = [var(bit) if offset >> k & 1 else neg(var(bit)) for k, bit in enumerate(self.bits)]
        return conj(next_(literal) if next_step else literal for literal in literals)

    def in_range(self, next_step: bool) -> Formula:
        """slugs' "variable limits" constraint; TRUE when every bit pattern is a value."""
        if 2 ** len(self.bits) == self.high - self.low + 1:
            return TRUE
        return compare([(self, next_step)], '<=', [self.high])


#: A term of an integer comparison: a constant, or an integer variable now (False) or next (True).
Term = int | tuple[IntegerVariable, bool]


def compare(left: list[Term], operator: str, right: list[Term]) -> Formula:
    """Expand ``sum(left) <operator> sum(right)`` to a disjunction over the valuations of the
    integer variables involved (terms: ints, or (IntegerVariable, next_step) pairs)."""
    unknowns: list[tuple[IntegerVariable, bool]] = sorted(
        {term for term in left + right if not isinstance(term, int)}, key=lambda term: (term[0].name, term[1]))
    ranges = [range(variable.low, variable.high + 1) for variable, _ in unknowns]
    size = 1
    for variable_values in ranges:
        size *= len(variable_values)
    if size > _MAX_EXPANSION:
        raise ValueError(f'integer comparison over {size} valuations is too large to expand')
    holds = COMPARATORS[operator]
    cases: list[Formula] = []
    for values in itertools.product(*ranges):
        value_of = dict(zip(unknowns, values))

        def total(terms: list[Term]) -> int:
            return sum(term if isinstance(term, int) else value_of[term] for term in terms)

        if holds(total(left), total(right)):
            cases.append(conj(variable.equals(value, next_step)
                              for (variable, next_step), value in value_of.items()))
    return disj(cases)
