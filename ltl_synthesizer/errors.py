"""Exceptions of the synthesizer; each carries an error-code name (``code``) and the bad ``item``.

A synthesis stopped or ended by the process runner is that runner's stop in the synthesizer's
words: SynthesisCancelledError is a ``respec.child_processes.errors.WorkCancelledError`` that
says "synthesis cancelled" (:func:`in_synthesis_words`).
"""

from __future__ import annotations

from respec.child_processes.errors import ChildDiedError, ChildWorkError, WorkCancelledError, WorkMemoryError, \
    WorkTimeoutError
from respec.vocabulary.errors import CodedError, ErrorCode


class SynthesisError(CodedError):
    """Base class: ``code`` names a SynthesisErrorCodes constant, ``item`` is the offending item."""

    code = ErrorCode.SYNTHESIS_FAILED


class UndeclaredPropositionError(SynthesisError):
    """A formula mentions a proposition that is declared neither as input nor as output."""

    code = ErrorCode.UNKNOWN_PROPOSITION


class NotGR1FormulaError(SynthesisError):
    """A formula is outside the GR(1) fragment (nested next, next in an initial condition...)."""

    code = ErrorCode.INVALID_FORMULA


class SynthesisCancelledError(SynthesisError, WorkCancelledError):
    """Synthesis was stopped by its cancel flag (``reason`` 'cancelled')."""

    code = ErrorCode.PREEMPTED

    def __init__(self, reason: str = 'cancelled'):
        super().__init__(reason, work='synthesis')


class SynthesisTimeoutError(SynthesisCancelledError, WorkTimeoutError):
    """Synthesis passed its deadline (``reason`` 'timeout', or what was going on then)."""

    code = ErrorCode.SYNTHESIS_TIMEOUT

    def __init__(self, reason: str = 'timeout', during: str = ''):
        super().__init__(reason)
        # What the synthesis was doing, and how large its task was (Interrupt.during()).
        self.during = during
        if during:
            self.args = (f'synthesis {reason} while {during}',)


class SynthesisMemoryError(SynthesisError, WorkMemoryError):
    """The synthesis needed more memory than its limit (``item`` is 'memory_limit')."""


class StrategyTooLargeError(SynthesisError):
    """A strategy with more transitions than the caller takes (``item``: 'max_strategy_edges'),
    found while it is extracted."""


class SynthesisProcessDiedError(SynthesisError, ChildDiedError):
    """The process running the synthesis ended without an answer."""


def in_synthesis_words(stopped: ChildWorkError) -> SynthesisError:
    """The synthesizer's error for the runner's ``stopped`` (its code and its words: 'synthesis
    cancelled', SYNTHESIS_TIMEOUT, ...); a synthesis error as it is."""
    if isinstance(stopped, SynthesisError):
        return stopped
    if isinstance(stopped, WorkTimeoutError):
        return SynthesisTimeoutError(stopped.reason)
    if isinstance(stopped, WorkCancelledError):
        return SynthesisCancelledError(stopped.reason)
    kind = (SynthesisMemoryError if isinstance(stopped, WorkMemoryError) else
            SynthesisProcessDiedError if isinstance(stopped, ChildDiedError) else SynthesisError)
    return kind(str(stopped), item=stopped.item)
