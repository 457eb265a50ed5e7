"""The base of every error the suite reports to its users."""

from __future__ import annotations


#: The code reported for an exception that is no CodedError: a programming error, whose
#: traceback is logged.
INTERNAL_ERROR = 'FAILURE'


class CodedError(Exception):
    """An error for users: ``code`` names a synthesis_msgs/SynthesisErrorCodes constant
    (the ROS nodes report it as that value) and ``item`` names the offending item."""

    code = 'FAILURE'

    def __init__(self, message: str, item=''):
        super().__init__(message)
        self.item = item

    def __reduce__(self):
        # Pickled whole (item and the subclass's own attributes), e.g. when a synthesis process
        # reports it: Exception's default pickling would call __init__ with the message only.
        return _rebuild_coded_error, (type(self), self.args, self.__dict__)


def _rebuild_coded_error(cls, args, state):
    error = Exception.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error
