"""The binary operators every reader shares: how tightly each binds, and the nodes it makes.

Operator precedence follows slugs' structured grammar (tools/StructuredSlugsParser/grammar.wi),
tightest first: ``!`` and ``next``, then ``&``, ``|``, ``^``, ``->``, ``<->``. As in that
grammar every binary operator is LEFT associative, so ``a -> b -> c`` means ``(a -> b) -> c``
(the same file means the same thing to slugs and to us; our printer always parenthesizes).
"""

from __future__ import annotations

from enum import IntEnum
from functools import lru_cache

from respec.ltl import Formula, conj, disj, iff, implies, neg, var


class Binding(IntEnum):
    """How tightly a binary operator binds, loosest first (all are left associative)."""

    IFF = 0
    IMPLIES = 1
    XOR = 2
    OR = 3
    AND = 4


BINDING = {'<->': Binding.IFF, '->': Binding.IMPLIES, '^': Binding.XOR, '|': Binding.OR, '&': Binding.AND}


# One node per proposition: large specifications mention each proposition many times.
shared_var = lru_cache(maxsize=1 << 16)(var)


def combine(operator: str, left: Formula, right: Formula) -> Formula:
    """A binary operator (its canonical spelling) applied to two operands."""
    if operator == '&':
        return conj([left, right])
    if operator == '|':
        return disj([left, right])
    if operator == '->':
        return implies(left, right)
    if operator == '<->':
        return iff(left, right)
    return xor(left, right)


def xor(left: Formula, right: Formula) -> Formula:
    """Exclusive or, which respec.ltl spells as a negated biimplication."""
    return neg(iff(left, right))
