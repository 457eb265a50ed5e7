"""The suite's error vocabulary: the error codes, the base of every error reported to users,
and how a message quotes a user's value.

ROS-free cores speak :class:`ErrorCode`; the ROS shell turns a code into a
``synthesis_msgs/SynthesisErrorCodes`` message by its integer value (the message declares the
same constants; a test keeps the two equal).
"""

from __future__ import annotations

import enum
import reprlib
import sys
from typing import Callable

#: How much of a user's value any message quotes: a refused value may be megabytes long.
QUOTED_CHARACTERS = 40
#: Longest ``item`` an error keeps (it names the bad item, sometimes by its value).
ITEM_CHARACTERS = 200



class ErrorCode(enum.StrEnum):
    """Every result code of the suite: a string, its name (so messages, JSON and comparisons
    read "INVALID_FORMULA"), with the integer ``number`` of synthesis_msgs/SynthesisErrorCodes
    (the original's codes plus the ones marked "added" there)."""

    number: int

    def __new__(cls, name: str, number: int) -> ErrorCode:
        member = str.__new__(cls, name)
        member._value_, member.number = name, number
        return member

    @staticmethod
    def _generate_next_value_(name: str, start: int, count: int, last_values: list[str]) -> str:
        return name

    SUCCESS = enum.auto(), 1
    FAILURE = enum.auto(), 99999
    # synthesis management
    BEHAVIOR_SYNTHESIS_FAILED = enum.auto(), -1
    INVALID_REQUEST = enum.auto(), -2
    SERVICE_UNAVAILABLE = enum.auto(), -3
    TIMEOUT = enum.auto(), -4
    BUSY = enum.auto(), -5
    PREEMPTED = enum.auto(), -9
    # specification compilation
    LTL_SPEC_COMPILATION_FAILED = enum.auto(), -10
    UNKNOWN_SYSTEM = enum.auto(), -11
    UNKNOWN_PROPOSITION = enum.auto(), -12
    INVALID_INITIAL_CONDITIONS = enum.auto(), -13
    INVALID_GOALS = enum.auto(), -14
    INVALID_SM_OUTCOMES = enum.auto(), -15
    INVALID_FORMULA = enum.auto(), -16
    ABSTRACTION_CONFIG_INVALID = enum.auto(), -17
    # LTL synthesis
    SYNTHESIS_FAILED = enum.auto(), -20
    SPEC_UNSYNTHESIZABLE = enum.auto(), -21
    SYNTHESIS_TIMEOUT = enum.auto(), -22
    INVALID_SPEC_NAME = enum.auto(), -23
    SYNTHESIZER_BACKEND_FAILED = enum.auto(), -24
    # state machine generation
    SM_GENERATION_FAILED = enum.auto(), -30
    NO_SYSTEMS_FILE = enum.auto(), -31
    NO_SYSTEM_CONFIG = enum.auto(), -32
    SYSTEM_CONFIG_NOT_FOUND = enum.auto(), -33
    CONFIG_FILE_INVALID = enum.auto(), -34
    CONFIG_AUTONOMY_INVALID = enum.auto(), -35
    CONFIG_VARIABLE_CONFIG_INVALID = enum.auto(), -36
    AUTOMATON_INVALID = enum.auto(), -37
    AUTOMATON_NO_INITIAL_STATE = enum.auto(), -38
    AUTOMATON_NEXT_STATE_INVALID = enum.auto(), -39
    AUTOMATON_INPUT_VALUATION_INVALID = enum.auto(), -40
    AUTOMATON_OUTPUT_VALUATION_INVALID = enum.auto(), -41
    CONFIG_USERDATA_INVALID = enum.auto(), -42

    @classmethod
    def from_number(cls, number: int) -> ErrorCode:
        """The code of ``number``; ValueError for a number this suite does not know."""
        try:
            return _BY_NUMBER[number]
        except KeyError:
            raise ValueError(f'{number} is no SynthesisErrorCodes value') from None

    @classmethod
    def name_of(cls, number: int) -> str:
        """The name of ``number``, or the number itself for a code this suite does not know
        (another server's answer is shown, never mistaken for a known code)."""
        code = _BY_NUMBER.get(number)
        return str(number) if code is None else code.name


_BY_NUMBER = {code.number: code for code in ErrorCode}

#: The code reported for an exception that is no CodedError: a programming error, whose
#: traceback is logged.
INTERNAL_ERROR = ErrorCode.FAILURE


class CodedError(Exception):
    """An error for users: ``code`` (an :class:`ErrorCode`) says what kind, ``item`` names the
    offending item."""

    code = ErrorCode.FAILURE

    def __init__(self, message: str, item: object = ''):
        super().__init__(message)
        self.item = item if not isinstance(item, str) or len(item) <= ITEM_CHARACTERS else item[:ITEM_CHARACTERS] + '...'

    def __reduce__(self) -> tuple[Callable[..., CodedError], tuple[type[CodedError], tuple[object, ...], dict[str, object]]]:
        # Pickled whole (item and the subclass's own attributes), e.g. when a synthesis process
        # reports it: Exception's default pickling would call __init__ with the message only.
        return _rebuild_coded_error, (type(self), self.args, self.__dict__)


class ControlFlowSignal(Exception):
    """Not an error: raised to unwind work that must stop (a goal its client cancelled, a
    queued job its caller gave up on). Whoever catches it answers in its own way; it is never
    reported as a failure or logged as a bug. Subclasses say what stopped."""


def _rebuild_coded_error(cls: type[CodedError], args: tuple[object, ...], state: dict[str, object]) -> CodedError:
    error = Exception.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


_SHORT_REPR = reprlib.Repr()
_SHORT_REPR.maxlevel, _SHORT_REPR.maxstring, _SHORT_REPR.maxother = 3, QUOTED_CHARACTERS + 2, QUOTED_CHARACTERS
_SHORT_REPR.maxlist = _SHORT_REPR.maxtuple = _SHORT_REPR.maxdict = _SHORT_REPR.maxset = 4


def quoted(value: object, length: int = QUOTED_CHARACTERS) -> str:
    """``value`` as every message quotes a user's input: ``'its start'...`` after ``length``
    characters. Strings are cut before they are quoted and other values are shown by a
    bounded repr, so quoting costs little whatever the size of the value."""
    if isinstance(value, str):
        return repr(value) if len(value) <= length else repr(value[:length]) + '...'
    shown = _SHORT_REPR.repr(value)
    return shown if len(shown) <= length else shown[:length] + '...'


class ExitStatus(enum.IntEnum):
    """The exit status of every command of the suite, one meaning per number (README, "Exit
    status"); a command stopped by SIGINT or SIGTERM exits with 128 + the signal's number."""

    meaning: str

    def __new__(cls, number: int, meaning: str) -> ExitStatus:
        member = int.__new__(cls, number)
        member._value_, member.meaning = number, meaning
        return member

    OK = 0, 'done as asked (`gr1synth`: realizable or not, as slugs)'
    FAILED = 1, ('the input or the task was refused: an error code of the pipeline (printed with '
                 'the item it names), a malformed specification (`gr1synth`, as slugs), a task that '
                 'cannot be done (`compile --diagnose`), no verified fix found (`repair`)')
    USAGE = 2, 'bad command line, or an argument file that cannot be read'
    TIMED_OUT = 3, 'a time limit ran out (`--timeout`, a goal\'s time limit)'
    OUT_OF_MEMORY = 4, 'a memory limit was exceeded (`gr1synth --memory-limit`)'
    UNAVAILABLE = 5, ('a server, node or port the command needs is missing or busy, or a program it needs is '
                      'not installed (the FlexBE engine of `execute --engine flexbe`)')
    OTHER_OUTCOME = 6, '`execute`, `start-behavior`: the behavior ended in another outcome than `--expect`'
    VIOLATIONS = 7, '`execute`: the trace check found violations, or the robot fell'
    NOT_FINISHED = 8, '`execute`: the run could not finish (robot-time limit, a state it cannot run)'

    @classmethod
    def for_error(cls, code: ErrorCode | str) -> ExitStatus:
        """The exit status of a command whose request ended with ``code`` (an ErrorCode or the
        name a server answered; one this suite does not know is a failure)."""
        try:
            # A lookup by value; mypy reads the call as the members' __new__(name, number).
            code = ErrorCode(code)  # type: ignore[call-arg]
        except ValueError:
            return cls.FAILED
        if code == ErrorCode.SUCCESS:
            return cls.OK
        if code in (ErrorCode.TIMEOUT, ErrorCode.SYNTHESIS_TIMEOUT):
            return cls.TIMED_OUT
        if code in (ErrorCode.SERVICE_UNAVAILABLE, ErrorCode.BUSY):
            return cls.UNAVAILABLE
        return cls.FAILED


def exit_status_help(*statuses: ExitStatus) -> str:
    """The ``Exit status:`` paragraph of a command's help, for the statuses it can end with."""
    import textwrap  # only for a help text (gr1synth synthesizes without it)
    lines = [textwrap.fill(f'{int(status)}  {status.meaning.replace("`", "")}', width=88,
                           initial_indent='  ', subsequent_indent='     ') for status in statuses]
    return '\n'.join(['Exit status:', *lines, '  130, 143  stopped by SIGINT (Ctrl-C) or SIGTERM'])


def unbuildable_value(error: ValueError | OverflowError) -> str:
    """Why YAML (or JSON) text parsed but a value of it could not be built, in a few words:
    PyYAML lets the constructors' ValueError through (an integer of more digits than Python
    converts, an impossible date), which would otherwise be an internal error."""
    text = str(error)
    if 'integer string conversion' in text:
        return f'an integer has more than {sys.get_int_max_str_digits()} digits'
    return f'a value cannot be read: {quoted(text, 100)}'

