"""The GUI's HTTP connections, bounded: a page keeps answering when clients hold many sockets open.

uvicorn keeps a connection that never sends a request open for as long as its client likes, and
accepts connections until the process runs out of file descriptors; then every accept fails
(EMFILE) and asyncio logs each failure: 1,100 idle connections under a 1,024-descriptor limit
left normal requests unanswered and wrote 222 MB of the same traceback in 15 s. Here:

- a connection that has not sent a whole request within IDLE_SECONDS is closed;
- at most ``max_connections`` are open (MAX_CONNECTIONS, well below the descriptor limit, which
  :func:`raise_descriptor_limit` lifts to its hard maximum): a new one past it closes the
  oldest connection that is not in the middle of a request, so a normal request still gets in;
- a log record repeated in a burst (an accept loop failing) is written once, then once more with
  how many were left out (:class:`RepeatedRecords`).
"""

from __future__ import annotations

import logging
import resource
import time
from collections import OrderedDict

from uvicorn.protocols.http.h11_impl import H11Protocol

#: Open connections at most (an event stream per open page, a request or two per page at once).
MAX_CONNECTIONS = 256
#: Seconds a connection may stay open without a request in progress before it is closed
#: (uvicorn's own keep-alive timeout, 5 s, covers the time after a response).
IDLE_SECONDS = 10.0


def raise_descriptor_limit() -> int:
    """Lift this process's soft limit of open files to its hard limit; return the limit now."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard != resource.RLIM_INFINITY and soft < hard:
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
            soft = hard
        except (ValueError, OSError):
            pass
    return soft


class BoundedH11Protocol(H11Protocol):
    """uvicorn's h11 protocol with an idle timeout from the first byte and a bound on open connections."""

    max_connections = MAX_CONNECTIONS
    idle_seconds = IDLE_SECONDS

    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        opened = _opened(self.server_state)
        opened[self] = time.monotonic()
        while len(opened) > self.max_connections:
            oldest_idle = next((connection for connection in opened if connection is not self
                                and not connection.busy()), None)
            if oldest_idle is None:
                break  # every other connection is mid-request: this one waits its turn in the kernel
            oldest_idle.transport.close()
            opened.pop(oldest_idle, None)
        self._idle_timer = self.loop.call_later(self.idle_seconds, self._close_if_idle)

    def connection_lost(self, exc) -> None:
        _opened(self.server_state).pop(self, None)
        self._idle_timer.cancel()
        super().connection_lost(exc)

    def busy(self) -> bool:
        """Whether a request is in progress on this connection (its response not yet sent)."""
        return self.cycle is not None and not self.cycle.response_complete

    def _close_if_idle(self) -> None:
        if self.cycle is None and not self.transport.is_closing():  # never sent a whole request
            self.transport.close()


def _opened(server_state) -> OrderedDict:
    """The server's open connections, oldest first (kept on uvicorn's shared server state)."""
    opened = getattr(server_state, 'opened_connections', None)
    if opened is None:
        opened = server_state.opened_connections = OrderedDict()
    return opened


class RepeatedRecords(logging.Filter):
    """Lets a record through once, then drops the same message for ``window`` seconds, and
    says how many were dropped with the next one let through."""

    def __init__(self, window: float = 10.0):
        super().__init__()
        self.window = window
        self._seen: dict[str, list] = {}  # message -> [let through at, dropped since]

    def filter(self, record: logging.LogRecord) -> bool:
        key = f'{record.name}:{record.levelno}:{record.msg}'
        now = time.monotonic()
        seen = self._seen.get(key)
        if seen is not None and now - seen[0] < self.window:
            seen[1] += 1
            return False
        if seen is not None and seen[1]:
            record.msg = f'{record.msg} (and {seen[1]} more like it in the last {now - seen[0]:.0f} s)'
        if len(self._seen) > 1000:
            self._seen.clear()
        self._seen[key] = [now, 0]
        return True


def install_repeat_filter(names=('asyncio', 'uvicorn.error')) -> RepeatedRecords:
    """One RepeatedRecords on the loggers that report failing accepts and connections."""
    repeats = RepeatedRecords()
    for name in names:
        logger = logging.getLogger(name)
        if not any(isinstance(existing, RepeatedRecords) for existing in logger.filters):
            logger.addFilter(repeats)
    return repeats
