"""The bounds every entry point enforces on what it is sent (ROS-free).

A request that breaks one is refused as INVALID_REQUEST naming the field, before any work is
done, and the offending value is never echoed whole (a 50 MB name must not travel back in the
error message). The ROS nodes check their requests with :func:`check_message`; the web GUI
refuses larger bodies than :data:`MAX_BODY_BYTES` with 413.
"""

from __future__ import annotations

import math
import re
import time

from respec.vocabulary.errors import CodedError, ErrorCode, quoted
from respec.untrusted import utf8_length
from synthesis_manager.requests import InvalidRequestError

#: Longest string accepted in any request field, in UTF-8 bytes.
MAX_STRING_BYTES = 64 * 1024
#: Most elements in any one list field of a request (goals, formulas, outcomes, ...).
MAX_LIST_LENGTH = 10_000
#: Most bytes (UTF-8) of all the strings of one request together.
MAX_MESSAGE_BYTES = 4 * 1024 * 1024
#: The server's default cap on a goal's time limit (parameter ``max_goal_timeout``), seconds.
DEFAULT_MAX_GOAL_TIMEOUT = 300.0
#: Largest HTTP request body the web GUI reads.
MAX_BODY_BYTES = 1024 * 1024
#: Fields whose strings are names (of a behavior, system, proposition, outcome, file): no
#: control character at all. Every other string may hold tabs and line breaks (formulas, YAML).
NAME_FIELDS = frozenset({'name', 'system', 'system_name', 'spec_name', 'specification_file_name',
                         'sm_outcomes', 'sys_props', 'env_props', 'request_id'})
# NUL (which C code would read as the end of the string) and the other control characters.
_CONTROL_IN_TEXT = re.compile('[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]')
_CONTROL_IN_NAME = re.compile('[\x00-\x1f\x7f-\x9f]')


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


def oversized_strings(message, path: str = 'request', limit: int = MAX_STRING_BYTES):
    """Yield ``(field path, string)`` for every string longer than ``limit`` bytes in a message
    (anything :func:`message_parts` reads: dict keys are searched too)."""
    for field_path, value in message_parts(message, path):
        # A character takes at most 4 bytes: shorter strings need no encoding to be checked.
        if isinstance(value, str) and len(value) * 4 > limit and utf8_length(value) > limit:
            yield field_path, value


def message_parts(message, path: str = 'request'):
    """Yield ``(field path, value)`` for every string and every list in a message (a ROS
    message, or a sequence or JSON-like dict of those), nested ones included, parents first."""
    if isinstance(message, str):
        yield path, message
    elif isinstance(message, (list, tuple)):
        yield path, message
        for index, element in enumerate(message):
            if isinstance(element, (str, list, tuple, dict)) or hasattr(element, 'get_fields_and_field_types'):
                yield from message_parts(element, f'{path}[{index}]')
    elif isinstance(message, dict):
        for key, element in message.items():
            yield f'{path} (a key)', key
            yield from message_parts(element, f'{path}.{key if len(str(key)) <= 100 else quoted(key)}')
    elif hasattr(message, 'get_fields_and_field_types'):
        for name in message.get_fields_and_field_types():
            yield from message_parts(getattr(message, name), f'{path}.{name}')


def check_message(message, path: str = 'request', limit: int = MAX_STRING_BYTES,
                  max_list: int | None = MAX_LIST_LENGTH, max_total: int | None = MAX_MESSAGE_BYTES):
    """Refuse a message before any work on it, naming the first field that breaks a bound: a
    string over ``limit`` bytes or holding a control character (:func:`check_text`), a list of
    more than ``max_list`` elements, strings of more than ``max_total`` bytes in all (None:
    no such bound)."""
    total = 0
    for field_path, value in message_parts(message, path):
        if not isinstance(value, str):
            if max_list is not None and len(value) > max_list:
                raise InvalidRequestError(f'{field_path} has {len(value)} elements; the limit is {max_list}',
                                          field_path)
            continue
        size = len(value) if value.isascii() else utf8_length(value)
        if size > limit:
            raise InvalidRequestError(too_long(field_path, value, limit), field_path)
        check_text(value, field_path)
        total += size
        if max_total is not None and total > max_total:
            raise InvalidRequestError(f'{path} is over {max_total} bytes in all (its strings up to {field_path} '
                                      f'take {total} bytes)', path)


def check_texts(message, path: str = 'request'):
    """Refuse a message with a control character in any string (:func:`check_text`): what a
    client must check before sending, since serialization cuts a string at its first NUL and
    the server would never see it."""
    for field_path, value in message_parts(message, path):
        if isinstance(value, str):
            check_text(value, field_path)


def is_name_field(field_path: str) -> bool:
    """Whether a field path (``goal.request.sm_outcomes[2]``) names a field of names."""
    return re.sub(r'\[\d+\]$', '', field_path).rsplit('.', 1)[-1] in NAME_FIELDS


def check_text(value: str, field_path: str, name: bool | None = None):
    """Refuse NUL and other control characters, naming the field and the character's place
    (a NUL would silently cut the string short where C code reads it). Names (``name``, or
    by default the fields of :data:`NAME_FIELDS`) may hold no control character at all;
    other text may hold tabs and line breaks."""
    pattern = _CONTROL_IN_NAME if (is_name_field(field_path) if name is None else name) else _CONTROL_IN_TEXT
    found = pattern.search(value)
    if found:
        raise InvalidRequestError(f'{field_path} holds the control character U+{ord(found.group()):04X} at '
                                  f'character {found.start()} (it starts {quoted(value)})', field_path)


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


def capped_timeout(requested: float, cap: float) -> float:
    """A goal's time limit under the server's cap (``max_goal_timeout``; 0: no cap), so that
    goals asking for 1e9 s cannot hold every worker. 0 (the server's per-stage defaults) stays 0."""
    return min(requested, cap) if requested and cap else requested


class GoalDeadline:
    """A goal's time limit over its whole pipeline: queue waits, every stage, the answer.

    ``limit`` seconds (0: none, each stage has only its own limit) count from ``started``
    (a time.monotonic() instant: when the goal was accepted, not when work on it began).
    ``requested``: what the goal asked for, when the server's cap made ``limit`` shorter (the
    answer then names both).
    """

    def __init__(self, limit: float, started: float | None = None, requested: float | None = None):
        self.limit = limit
        self.requested = requested if requested is not None and requested > limit else None
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

    def capped(self) -> str:
        """Says that the server's cap shortened the goal's limit ('' when it did not)."""
        if self.requested is None:
            return ''
        return (f'the goal asked for {self.requested:g} s; the server\'s max_goal_timeout caps it '
                f'at {self.limit:g} s')

    def timed_out(self, stage: str) -> GoalTimeoutError:
        capped = f'; {self.capped()}' if self.requested is not None else ''
        return GoalTimeoutError(f'the goal\'s time limit of {self.limit:g} s passed ({stage}; the limit counts '
                            f'the whole pipeline, waiting included{capped})', 'timeout')
