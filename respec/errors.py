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
