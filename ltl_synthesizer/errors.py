"""Exceptions of the synthesizer; each carries an error-code name (``code``) and the bad ``item``."""

from __future__ import annotations

from respec.errors import CodedError


class SynthesisError(CodedError):
    """Base class: ``code`` names a SynthesisErrorCodes constant, ``item`` is the offending item."""

    code = 'SYNTHESIS_FAILED'


class UnknownPropositionError(SynthesisError):
    """A formula mentions a proposition that is declared neither as input nor as output."""

    code = 'UNKNOWN_PROPOSITION'


class InvalidFormulaError(SynthesisError):
    """A formula is outside the GR(1) fragment (nested next, next in an initial condition...)."""

    code = 'INVALID_FORMULA'


class SynthesisCancelled(SynthesisError):
    """Synthesis was stopped by the cancel flag (``reason='cancelled'``) or the deadline ('timeout')."""

    def __init__(self, reason: str):
        super().__init__(f'synthesis {reason}', item=reason)
        self.reason = reason
        self.code = 'PREEMPTED' if reason == 'cancelled' else 'SYNTHESIS_TIMEOUT'
