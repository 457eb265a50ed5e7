"""How deeply formulas may nest, everywhere (gr1synth, every node, the GUI): one limit.

Formula trees are walked recursively (parsing, printing, merging, pickling to a synthesis
process). The parsers refuse formulas nested deeper than :data:`MAX_FORMULA_NESTING` with
INVALID_FORMULA naming the place. Work on formulas that deep needs more Python frames than
the default recursion limit and more C stack than a default thread has (slugs reads about
3,000 levels), so it runs through :func:`run_with_deep_stack`: on a thread whose stack is
sized for it, with the recursion limit raised only while such work runs and restored after.

Never process-wide: a raised limit on a thread with an ordinary stack (the main thread's
8 MB) turns deep input to any C-recursive decoder (json, pickle) into a SIGSEGV instead of
a RecursionError; a GUI died of a 100,000-deep JSON body that way (issue 34). CPython has one
recursion limit per interpreter, so while deep work runs other threads see it too; the HTTP
bodies and YAML options those threads decode are depth-checked before they are parsed.
"""

from __future__ import annotations

import sys
import threading
from typing import Callable, ParamSpec, TypeVar

#: Deepest nesting of parentheses and unary operators (``!``, ``next``) in one formula.
MAX_FORMULA_NESTING = 10_000
#: Stack of threads that walk formulas (virtual memory: only what is used is resident).
DEEP_STACK_BYTES = 256 << 20
#: Python frames those threads may stack (a nesting level takes a few).
DEEP_RECURSION_LIMIT = 200_000

_DEEP_THREAD_NAME = 'deep-formulas'
_P = ParamSpec('_P')
_T = TypeVar('_T')
_limit_lock = threading.Lock()
_deep_callers = 0  # deep work running now, in any thread
_limit_before = sys.getrecursionlimit()  # the limit to restore when the last of them ends (read at its start)


def _raise_limit() -> None:
    global _deep_callers, _limit_before
    with _limit_lock:
        if _deep_callers == 0:
            _limit_before = sys.getrecursionlimit()
            sys.setrecursionlimit(max(_limit_before, DEEP_RECURSION_LIMIT))
        _deep_callers += 1


def _restore_limit() -> None:
    global _deep_callers
    with _limit_lock:
        _deep_callers -= 1
        if _deep_callers == 0:
            sys.setrecursionlimit(_limit_before)


def in_deep_thread() -> bool:
    """True in a thread started by :func:`start_deep_thread` (its stack is sized for formulas)."""
    return isinstance(threading.current_thread(), _DeepThread)


class _DeepThread(threading.Thread):
    """A thread started by :func:`start_deep_thread`."""


def start_deep_thread(target: Callable[[], object], name: str = _DEEP_THREAD_NAME, daemon: bool = True) -> threading.Thread:
    """Start ``target()`` on a thread with a stack of DEEP_STACK_BYTES (the recursion limit is
    left as it is: run formula work in it through :func:`run_with_deep_stack`)."""
    with _limit_lock:  # threading.stack_size is process-wide: set only for this thread's start
        previous = threading.stack_size(DEEP_STACK_BYTES)
        try:
            thread = _DeepThread(target=target, name=name, daemon=daemon)
            thread.start()
        finally:
            threading.stack_size(previous)
    return thread


def run_with_deep_stack(function: Callable[_P, _T], *args: _P.args, **kwargs: _P.kwargs) -> _T:
    """``function(*args, **kwargs)`` with room for formulas nested MAX_FORMULA_NESTING deep: in
    this thread when it is a deep one, else in a new one (its exceptions are raised here). The
    recursion limit is raised while it runs and restored when no deep work is left."""
    if in_deep_thread():
        _raise_limit()
        try:
            return function(*args, **kwargs)
        finally:
            _restore_limit()
    values: list[_T] = []
    errors: list[BaseException] = []

    def target() -> None:
        try:
            values.append(run_with_deep_stack(function, *args, **kwargs))
        except BaseException as error:  # noqa: BLE001 -- re-raised in the caller's thread
            errors.append(error)

    worker = start_deep_thread(target, name=getattr(function, '__name__', _DEEP_THREAD_NAME))
    while worker.is_alive():  # a timed join keeps Ctrl-C working in the main thread
        worker.join(0.1)
    if errors:
        raise errors[0]
    return values[0]


def too_deep(levels: int = MAX_FORMULA_NESTING) -> str:
    """The problem statement of a formula nested deeper than ``levels``."""
    return f'formula nested deeper than {levels} levels (parentheses, ! and next)'
