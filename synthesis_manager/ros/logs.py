"""Logging a node's per-request lines without rclpy's caller lookup.

rclpy's logger (Jazzy) finds its caller for every call, even without ``once`` or ``throttle``
filters, through ``inspect.getframeinfo``, which reads the caller's source file: 2.5 ms a
line on a loaded 2-core machine, and a third of the server's spinning thread in a 200-goal
burst where every goal ended with a warning (its stage's and the server's). A QuickLogger
writes the same line (same logger name and severity, the caller's function, file and line,
to the console and /rosout) through rcutils directly. For lines written once, rclpy's own
logger is as good.
"""

from __future__ import annotations

import sys

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.logging import LoggingSeverity


#: The longest line a node logs: a message quoting a whole input (a formula, a file) is cut,
#: saying how much was left out (a 522 MB line once came from one request).
MAX_LOG_LINE_CHARS = 4000


def bounded_line(message: str, limit: int = MAX_LOG_LINE_CHARS) -> str:
    """``message`` cut to ``limit`` characters, saying how many were left out."""
    if len(message) <= limit:
        return message
    return f'{message[:limit]}... ({len(message) - limit} more characters not logged)'


class QuickLogger:
    """``info``, ``warning`` and ``error`` of a node's logger, without the caller lookup; each
    line at most MAX_LOG_LINE_CHARS long."""

    def __init__(self, logger):
        self.logger = logger

    def info(self, message: str) -> None:
        self._log(LoggingSeverity.INFO, message)

    def warning(self, message: str) -> None:
        self._log(LoggingSeverity.WARN, message)

    def error(self, message: str) -> None:
        self._log(LoggingSeverity.ERROR, message)

    def _log(self, severity: LoggingSeverity, message: str) -> None:
        if not self.logger.is_enabled_for(severity):
            return
        caller = sys._getframe(2)  # noqa: SLF001 - the frame that called info/warning/error, as logging finds it
        _rclpy.rclpy_logging_rcutils_log(severity, self.logger.name, bounded_line(str(message)), caller.f_code.co_name,
                                         caller.f_code.co_filename, caller.f_lineno)
