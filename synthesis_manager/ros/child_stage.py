"""A stage node's large requests, worked on in child processes within the node's limits.

The compilation and the state-machine generation nodes do small requests at once in their own
process, and hand large ones (megabytes of custom formulas, automata of thousands of states)
to this: a child process (``ltl_synthesizer.isolated``) per request, at most ``workers`` at once
and ``waiting`` more in order (then BUSY), each killed at the node's ``timeout`` counted from
the request's arrival (TIMEOUT), beyond its ``memory_limit_mb`` of growth (the stage's failure
code naming the limit), at shutdown (PREEMPTED) or when its caller cancels it by its request id
(:meth:`ChildStage.cancel`, the node's ``<service>/cancel``; PREEMPTED), so one request can
neither hold the node's interpreter for seconds nor grow it without bound, nor work on for a
goal that was cancelled.

    children = ChildStage(node, 'sm_generation', workers=1, waiting=50, name='generation',
                          what='state machine generation', failed=ErrorCode.SM_GENERATION_FAILED)
    try:
        value = await children.run(function, args, kwargs, size='40,002 automaton states')
    except StageStopped as stopped:
        response.error_code = stopped.error_code
"""

from __future__ import annotations

import threading
import time

from ltl_synthesizer import SynthesisCancelledError
from ltl_synthesizer.errors import SynthesisMemoryError
from ltl_synthesizer.isolated import SERVER_CHILD_NICENESS, SynthesisProcesses
from respec.errors import ControlFlowSignal, ErrorCode
from synthesis_manager.ros.conversions import error_code
from synthesis_manager.ros.stage_calls import LookTimer
from synthesis_manager.ros.worker_pool import Abandoned, WorkerPool, executor_waker

QUEUE_LOOK_SECONDS = 0.5


class StageStopped(ControlFlowSignal):
    """Not an error of the node: a request's work in a child was stopped by its time or memory
    limit or by shutdown; ``error_code`` answers the request."""

    def __init__(self, error_code):
        super().__init__(error_code.message)
        self.error_code = error_code


class _StopFlag:
    """Set once the node stops or this request is cancelled (what a child's ``cancel`` asks)."""

    def __init__(self, stopping: threading.Event):
        self.stopping, self.cancelled = stopping, threading.Event()

    def is_set(self) -> bool:
        return self.stopping.is_set() or self.cancelled.is_set()


class ChildStage:
    """Large requests of ``node`` in child processes (module docstring). The node declares the
    settings ``timeout`` (s) and ``memory_limit_mb``; ``what`` starts the messages and
    ``failed`` is the code of work beyond its memory limit."""

    def __init__(self, node, preload: str, workers: int, waiting: int, name: str, what: str, failed: ErrorCode):
        self.node, self.what, self.failed = node, what, failed
        self.stopping = threading.Event()
        self.pool = WorkerPool(workers, waiting, name=name)
        # Queued requests see their deadline pass at most this late; stages rarely queue.
        self.looks = LookTimer(node, QUEUE_LOOK_SECONDS)
        self.processes = SynthesisProcesses(niceness=SERVER_CHILD_NICENESS, preload=preload)
        self._cancels: dict[str, _StopFlag] = {}  # by request id, while the request runs
        self._lock = threading.Lock()

    @property
    def running_requests(self) -> list[str]:
        """The ids of the requests with work here (waiting or in a child), in arrival order."""
        with self._lock:
            return list(self._cancels)

    def cancel(self, request_id: str) -> bool:
        """Stop the work of request ``request_id``; whether it was running."""
        with self._lock:
            stop = self._cancels.get(request_id)
        if stop is not None:
            stop.cancelled.set()
        return stop is not None

    async def run(self, function, args=(), kwargs=None, size: str = '', arrival: float | None = None,
                  requested: float = 0.0, request_id: str = ''):
        """``function(*args, **kwargs)`` in a child, awaited; raises StageStopped with the
        answer when the time or memory limit, shutdown or a cancel of ``request_id`` ends it
        (``size`` says how large the request was, in the message; the time limit, the node's or
        the shorter ``requested`` one when it is over 0, counts from ``arrival``, a
        time.monotonic() instant, or from now)."""
        timeout = self.node.settings.timeout
        if requested > 0:
            timeout = min(timeout, requested)
        deadline = (time.monotonic() if arrival is None else arrival) + timeout
        stop = _StopFlag(self.stopping)
        with self._lock:
            if request_id:
                self._cancels[request_id] = stop
        try:
            with self.looks.waiting():
                return await self.pool.run(self._in_child, function, args, kwargs, deadline, stop,
                                           wake=executor_waker(self.node),
                                           give_up=lambda: stop.is_set() or time.monotonic() > deadline)
        except (Abandoned, SynthesisCancelledError):  # a timeout is a cancel by the deadline
            why = ('cancelled' if stop.cancelled.is_set() else 'shutdown' if self.stopping.is_set()
                   else 'time limit')
            raise StageStopped(error_code(ErrorCode.TIMEOUT if why == 'time limit' else ErrorCode.PREEMPTED,
                                          f'{self.what} stopped: {why} ({timeout:g} s for {size})')) from None
        except SynthesisMemoryError as error:
            raise StageStopped(error_code(self.failed, f'{self.what} failed: {error} (memory_limit_mb, {size})')) from None
        finally:
            with self._lock:
                if self._cancels.get(request_id) is stop:
                    del self._cancels[request_id]

    def _in_child(self, function, args, kwargs, deadline: float, stop: _StopFlag):
        if stop.is_set() or time.monotonic() > deadline:
            raise SynthesisCancelledError('stopped while waiting')
        # ``cancel`` is asked only is_set(); isolated.py annotates it as an Event (to become a
        # Protocol once isolated.py has moved into respec and is checked).
        return self.processes.call(function, args, kwargs, cancel=stop, deadline=deadline,  # type: ignore[arg-type]
                                   memory_limit=self.node.settings.memory_limit_mb * 2**20)

    def stop(self) -> None:
        """Kill every child, busy or idle, and refuse further work (at shutdown)."""
        self.stopping.set()
        self.processes.close()
