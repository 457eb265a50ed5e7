"""Exceptions of the synthesizer; each carries an error-code name (``code``) and the bad ``item``."""

from __future__ import annotations

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


class SynthesisCancelledError(SynthesisError):
    """Synthesis was stopped by its cancel flag (``reason`` 'cancelled')."""

    code = ErrorCode.PREEMPTED

    def __init__(self, reason: str = 'cancelled'):
        super().__init__(f'synthesis {reason}', item=reason)
        self.reason = reason


class SynthesisTimeoutError(SynthesisCancelledError):
    """Synthesis passed its deadline (``reason`` 'timeout', or what was going on then)."""

    code = ErrorCode.SYNTHESIS_TIMEOUT

    def __init__(self, reason: str = 'timeout', during: str = ''):
        super().__init__(reason)
        # What the synthesis was doing, and how large its task was (Interrupt.during()).
        self.during = during
        if during:
            self.args = (f'synthesis {reason} while {during}',)


class SynthesisMemoryError(SynthesisError):
    """The synthesis needed more memory than its limit (``item`` is 'memory_limit')."""


class StrategyTooLargeError(SynthesisError):
    """A strategy with more transitions than the caller takes (``item``: 'max_strategy_edges'),
    found while it is extracted."""
