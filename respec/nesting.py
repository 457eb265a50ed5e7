"""How deeply formulas may nest, everywhere (gr1synth, every node, the GUI): one limit.

Formula trees are walked recursively (parsing, printing, merging, pickling to a synthesis
process). The parsers refuse formulas nested deeper than :data:`MAX_FORMULA_NESTING` with
INVALID_FORMULA naming the place, and every process that reads formulas calls
:func:`allow_deep_formulas` first, so that threads started afterwards have room for formulas
that deep (slugs reads about 3,000 levels).
"""

from __future__ import annotations

import sys
import threading

#: Deepest nesting of parentheses and unary operators (``!``, ``next``) in one formula.
MAX_FORMULA_NESTING = 10_000
#: Stack of threads that walk formulas (virtual memory: only what is used is resident).
DEEP_STACK_BYTES = 256 << 20
#: Python frames those threads may stack (a nesting level takes a few).
DEEP_RECURSION_LIMIT = 200_000


def allow_deep_formulas() -> None:
    """Let threads started from now on walk formulas MAX_FORMULA_NESTING deep."""
    threading.stack_size(max(threading.stack_size(), DEEP_STACK_BYTES))
    sys.setrecursionlimit(max(sys.getrecursionlimit(), DEEP_RECURSION_LIMIT))


def too_deep(levels: int = MAX_FORMULA_NESTING) -> str:
    """The problem statement of a formula nested deeper than ``levels``."""
    return f'formula nested deeper than {levels} levels (parentheses, ! and next)'
