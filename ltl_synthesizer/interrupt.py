"""Stopping a synthesis on request (a process concern, kept out of the game and the solver):
a cancel flag, a deadline and a memory limit (``Limits``), checked by every long loop
(``Interrupt``)."""

from __future__ import annotations

import dataclasses
import threading
import time
from dataclasses import dataclass

from ltl_synthesizer.errors import SynthesisCancelledError, SynthesisMemoryError, SynthesisTimeoutError
from respec.child_processes.memory import resident_memory

# Default memory limit of one synthesis: BDD memory, in bytes.
DEFAULT_MEMORY_LIMIT = 2 * 2**30


@dataclass(frozen=True)
class Limits:
    """When a synthesis must stop: once ``cancel`` (a threading.Event) is set, at ``deadline``
    (a ``time.monotonic()`` instant), or beyond ``memory_limit`` bytes (None: no limit).

    Plain data, given to every entry point of the synthesizer; the process doing the work
    makes the ``Interrupt`` that checks them.
    """

    cancel: threading.Event | None = None
    deadline: float | None = None
    memory_limit: int | None = DEFAULT_MEMORY_LIMIT

    def interrupt(self) -> Interrupt:
        """The check of these limits for this process (its memory counted from now)."""
        return Interrupt(self.cancel, self.deadline, self.memory_limit)

    def without_cancel(self) -> Limits:
        """These limits for a child process (the flag stays with the parent, which ends the
        child when it is set; an Event cannot be sent)."""
        return dataclasses.replace(self, cancel=None)


class Interrupt:
    """Stops a synthesis on request: a cancel flag, a deadline (a ``time.monotonic()``
    instant) and a memory limit in bytes. Every long loop of the synthesizer (translation,
    fixpoints, reachability, extraction, explanation, parsing) calls ``check()``, so a
    synthesis stops within a few milliseconds of the request, beyond the duration of one BDD
    operation. The object is also a plain callable (for respec's parser).

    The memory limit bounds the BDDs (CUDD's own limit, set by the game, fails the operation
    that would exceed it) and the process's growth in resident memory since this object was
    made (the explicit strategy and the rest), polled every ``MEMORY_CHECK_SECONDS``.
    """

    MEMORY_CHECK_SECONDS = 0.1

    def __init__(self, cancel: threading.Event | None = None, deadline: float | None = None,
                 memory_limit: int | None = None):
        self.cancel = cancel
        self.deadline = deadline
        self.memory_limit = memory_limit
        self._baseline_memory = resident_memory() if memory_limit is not None else 0
        self._memory_checked_at = time.monotonic()
        # What the work is doing and its size measure, named when a limit stops it (the
        # synthesizer sets them: 'solving the game', '80 inputs and 82 outputs (...)').
        self.stage = ''
        self.size = ''

    def during(self) -> str:
        """The stage and the size measure, as a limit's message names them ('' unknown)."""
        if not self.stage:
            return ''
        return f'{self.stage} ({self.size})' if self.size else self.stage

    def check(self) -> None:
        if self.cancel is not None and self.cancel.is_set():
            raise SynthesisCancelledError('cancelled')
        now = time.monotonic()
        if self.deadline is not None and now >= self.deadline:
            raise SynthesisTimeoutError(during=self.during())
        if self.memory_limit is not None and now - self._memory_checked_at >= self.MEMORY_CHECK_SECONDS:
            self._memory_checked_at = now
            if resident_memory() - self._baseline_memory > self.memory_limit:
                raise memory_exceeded(self.memory_limit, self.during())

    __call__ = check


def memory_exceeded(limit: int, during: str = '') -> SynthesisMemoryError:
    where = f' while {during}' if during else ''
    return SynthesisMemoryError(
        f'synthesis needs more than its memory limit of {limit / 2**20:.0f} MB{where} '
        '(memory_limit); simplify the specification or raise the limit', item='memory_limit')
