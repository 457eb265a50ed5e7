"""The bounds every entry point enforces on what it is sent (ROS-free).

A request that breaks one is refused as INVALID_REQUEST naming the field, before any work is
done, and the offending value is never echoed whole (a 50 MB name must not travel back in the
error message). The ROS nodes check their requests with :func:`check_message`; the web GUI
refuses larger bodies than :data:`MAX_BODY_BYTES` with 413.
"""

from __future__ import annotations

import math
import time

from respec.errors import CodedError, ErrorCode, quoted
from synthesis_manager.requests import InvalidRequestError

#: Longest string accepted in any request field, in UTF-8 bytes.
MAX_STRING_BYTES = 64 * 1024
#: Largest HTTP request body the web GUI reads.
MAX_BODY_BYTES = 1024 * 1024


def check_timeout(value, item: str = 'timeout') -> float:
    """A time limit in seconds: finite and >= 0 (0 means the server's default)."""
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        raise InvalidRequestError(f'{item} must be a number of seconds, got {quoted(value)}') from None
    if not math.isfinite(seconds) or seconds < 0:
        raise InvalidRequestError(f'{item} must be a finite number of seconds >= 0 (0: the default), '
                             f'got {quoted(value)}')
    return seconds


def utf8_length(text: str) -> int:
    return len(text.encode('utf-8', errors='surrogatepass'))


def oversized_strings(message, path: str = 'request', limit: int = MAX_STRING_BYTES):
    """Yield ``(field path, string)`` for every string longer than ``limit`` bytes in a message.

    ``message`` is a ROS message (anything with ``get_fields_and_field_types()``), a string,
    or a sequence or (JSON-like) dict of those; nested messages, arrays and dicts are searched
    too, dict keys included.
    """
    if isinstance(message, str):
        # A character takes at most 4 bytes: shorter strings need no encoding to be checked.
        if len(message) * 4 > limit and utf8_length(message) > limit:
            yield path, message
    elif isinstance(message, (list, tuple)):
        for index, element in enumerate(message):
            if isinstance(element, str) or hasattr(element, 'get_fields_and_field_types'):
                yield from oversized_strings(element, f'{path}[{index}]', limit)
    elif isinstance(message, dict):
        for key, element in message.items():
            if list(oversized_strings(key, path, limit)):
                yield f'{path} (a key)', key
            else:
                yield from oversized_strings(element, f'{path}.{key}', limit)
    elif hasattr(message, 'get_fields_and_field_types'):
        for name in message.get_fields_and_field_types():
            yield from oversized_strings(getattr(message, name), f'{path}.{name}', limit)


def check_message(message, path: str = 'request', limit: int = MAX_STRING_BYTES):
    """Refuse a message with an oversized string field, naming the first such field."""
    for field_path, value in oversized_strings(message, path, limit):
        raise InvalidRequestError(too_long(field_path, value, limit))


def too_long(field_path: str, value: str, limit: int = MAX_STRING_BYTES) -> str:
    """The error message for an oversized string, quoting only its start."""
    return (f'{field_path} is {utf8_length(value)} bytes long; the limit is {limit} bytes '
            f'(it starts {quoted(value)})')


class BusyError(CodedError):
    """Too much work is in progress (goals, queued syntheses, GUI jobs or simulations): the
    request is refused, nothing was started. ``retry_after``: seconds after which trying again
    may work, when that is known (the GUI sends it as Retry-After)."""

    code = ErrorCode.BUSY

    def __init__(self, message: str, item='', retry_after: int | None = None):
        super().__init__(message, item)
        self.retry_after = retry_after


class GoalTimeoutError(CodedError):
    """The goal's own time limit passed (its whole pipeline, queues included)."""

    code = ErrorCode.TIMEOUT


class GoalDeadline:
    """A goal's time limit over its whole pipeline: queue waits, every stage, the answer.

    ``limit`` seconds (0: none, each stage has only its own limit) count from ``started``
    (a time.monotonic() instant: when the goal was accepted, not when work on it began).
    """

    def __init__(self, limit: float, started: float | None = None):
        self.limit = limit
        self.deadline = (time.monotonic() if started is None else started) + limit if limit else None

    def stage_limit(self, stage_limit: float, stage: str) -> float:
        """Seconds ``stage`` may take: its own limit, cut to what is left of the goal's;
        GoalTimeoutError when nothing is left."""
        if self.deadline is None:
            return stage_limit
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise self.timed_out(stage)
        return min(stage_limit, left)

    def passed(self) -> bool:
        return self.deadline is not None and time.monotonic() >= self.deadline

    def timed_out(self, stage: str) -> GoalTimeoutError:
        return GoalTimeoutError(f'the goal\'s time limit of {self.limit:g} s passed ({stage}; the limit counts '
                            'the whole pipeline, waiting included)', 'timeout')
