"""How a node answers a request that raised: user errors by their code, bugs with a traceback.

A ``CodedError`` is bad input (or a known failure) and becomes its SynthesisErrorCodes
constant. Any other exception is a programming error: it is logged with its traceback and
answered as ``INTERNAL_ERROR``, so the node keeps serving and the bug stays visible.
"""

from __future__ import annotations

import traceback

from respec.vocabulary.errors import INTERNAL_ERROR, CodedError
from synthesis_manager.ros.conversions import error_code
from synthesis_manager.ros.logs import bounded_line
from synthesis_msgs.msg import SynthesisErrorCodes


def reported_error(error: BaseException, logger, what: str) -> SynthesisErrorCodes:
    """The error code answering a request that ``error`` ended; ``what`` starts the message."""
    if isinstance(error, CodedError):
        return error_code(error.code, f'{what}: {error}')
    log_internal_error(logger, what, error)
    return error_code(INTERNAL_ERROR, f'{what}: internal error: {error!r}')


def log_internal_error(logger, what: str, error: BaseException) -> None:
    logger.error(bounded_line(f'{what}: internal error\n' + ''.join(traceback.format_exception(error)).rstrip()))
