"""What the process runner raises when it stops work in a child or the child dies.

Each kind is a CodedError whose code says what happened; a caller that names its work in its
own words subclasses them (the synthesizer: ``SynthesisCancelledError`` is a
:class:`WorkCancelledError` that says "synthesis cancelled", ``ltl_synthesizer.errors``).
"""

from __future__ import annotations

from respec.vocabulary.errors import CodedError, ErrorCode


class ChildWorkError(CodedError):
    """Work in a child process ended without its answer: stopped, or its process died (or its
    answer could not be sent back)."""


class WorkCancelledError(ChildWorkError):
    """The work was stopped by its cancel flag or a shutdown (``reason`` 'cancelled'); the
    message is ``'<work> <reason>'``."""

    code = ErrorCode.PREEMPTED

    def __init__(self, reason: str = 'cancelled', work: str = 'work') -> None:
        super().__init__(f'{work} {reason}', item=reason)
        self.reason = reason


class WorkTimeoutError(WorkCancelledError):
    """The work passed its deadline (``reason`` 'timeout')."""

    code = ErrorCode.TIMEOUT

    def __init__(self, reason: str = 'timeout', work: str = 'work') -> None:
        super().__init__(reason, work)


class WorkMemoryError(ChildWorkError):
    """The work grew its process beyond its memory limit (``item`` 'memory_limit'), or the
    process tree beyond its sum limit (``item`` 'memory_sum_limit')."""


class ChildDiedError(ChildWorkError):
    """The child process ended without an answer (killed from outside, crashed)."""
