"""Exceptions of the synthesizer; each carries an error-code name (``code``) and the bad ``item``."""

from __future__ import annotations

from respec.errors import CodedError, ErrorCode


class SynthesisError(CodedError):
    """Base class: ``code`` names a SynthesisErrorCodes constant, ``item`` is the offending item."""

    code = ErrorCode.SYNTHESIS_FAILED


class UndeclaredPropositionError(SynthesisError):
    """A formula mentions a proposition that is declared neither as input nor as output."""

    code = ErrorCode.UNKNOWN_PROPOSITION


class NotGR1FormulaError(SynthesisError):
    """A formula is outside the GR(1) fragment (nested next, next in an initial condition...)."""

    code = ErrorCode.INVALID_FORMULA


class SynthesisCancelled(SynthesisError):
    """Synthesis was stopped by the cancel flag (``reason='cancelled'``) or the deadline ('timeout').

    ``SynthesisCancelled('timeout')`` makes a :class:`SynthesisTimedOut`, so that each code
    belongs to a class.
    """

    code = ErrorCode.PREEMPTED

    def __new__(cls, reason: str = 'cancelled'):
        if cls is SynthesisCancelled and reason == 'timeout':
            cls = SynthesisTimedOut
        return super().__new__(cls, reason)

    def __init__(self, reason: str = 'cancelled'):
        super().__init__(f'synthesis {reason}', item=reason)
        self.reason = reason


class SynthesisTimedOut(SynthesisCancelled):
    """Synthesis passed its deadline."""

    code = ErrorCode.SYNTHESIS_TIMEOUT

    def __init__(self, reason: str = 'timeout'):
        super().__init__(reason)


class SynthesisMemoryExceeded(SynthesisError):
    """The synthesis needed more memory than its limit (``item`` is 'memory_limit')."""
