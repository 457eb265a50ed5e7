"""The base of every error the suite reports to its users."""

from __future__ import annotations

import reprlib

#: How much of a user's value any message quotes: a refused value may be megabytes long.
QUOTED_CHARACTERS = 40
#: Longest ``item`` an error keeps (it names the bad item, sometimes by its value).
ITEM_CHARACTERS = 200

#: The code reported for an exception that is no CodedError: a programming error, whose
#: traceback is logged.
INTERNAL_ERROR = 'FAILURE'


class CodedError(Exception):
    """An error for users: ``code`` names a synthesis_msgs/SynthesisErrorCodes constant
    (the ROS nodes report it as that value) and ``item`` names the offending item."""

    code = 'FAILURE'

    def __init__(self, message: str, item=''):
        super().__init__(message)
        self.item = item if not isinstance(item, str) or len(item) <= ITEM_CHARACTERS else item[:ITEM_CHARACTERS] + '...'

    def __reduce__(self):
        # Pickled whole (item and the subclass's own attributes), e.g. when a synthesis process
        # reports it: Exception's default pickling would call __init__ with the message only.
        return _rebuild_coded_error, (type(self), self.args, self.__dict__)


def _rebuild_coded_error(cls, args, state):
    error = Exception.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


_SHORT_REPR = reprlib.Repr()
_SHORT_REPR.maxlevel, _SHORT_REPR.maxstring, _SHORT_REPR.maxother = 3, QUOTED_CHARACTERS + 2, QUOTED_CHARACTERS
_SHORT_REPR.maxlist = _SHORT_REPR.maxtuple = _SHORT_REPR.maxdict = _SHORT_REPR.maxset = 4


def quoted(value, length: int = QUOTED_CHARACTERS) -> str:
    """``value`` as every message quotes a user's input: ``'its start'...`` after ``length``
    characters. Strings are cut before they are quoted and other values are shown by a
    bounded repr, so quoting costs little whatever the size of the value."""
    if isinstance(value, str):
        return repr(value) if len(value) <= length else repr(value[:length]) + '...'
    shown = _SHORT_REPR.repr(value)
    return shown if len(shown) <= length else shown[:length] + '...'
