"""A stage node's large requests, worked on in child processes within the node's limits.

The compilation and the state-machine generation nodes do small requests at once in their own
process, and hand large ones (megabytes of custom formulas, automata of thousands of states)
to this: a child process (``ltl_synthesizer.isolated``) per request, at most ``workers`` at once
and ``waiting`` more in order (then BUSY), each killed at the node's ``timeout`` counted from
the request's arrival (TIMEOUT), beyond its ``memory_limit_mb`` of growth (the stage's failure
code naming the limit) or at shutdown (PREEMPTED), so one request can neither hold the node's
interpreter for seconds nor grow it without bound.

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
from synthesis_manager.ros.worker_pool import Abandoned, WorkerPool, executor_waker


class StageStopped(ControlFlowSignal):
    """Not an error of the node: a request's work in a child was stopped by its time or memory
    limit or by shutdown; ``error_code`` answers the request."""

    def __init__(self, error_code):
        super().__init__(error_code.message)
        self.error_code = error_code


class ChildStage:
    """Large requests of ``node`` in child processes (module docstring). The node declares the
    parameters ``timeout`` (s) and ``memory_limit_mb``; ``what`` starts the messages and
    ``failed`` is the code of work beyond its memory limit."""

    def __init__(self, node, preload: str, workers: int, waiting: int, name: str, what: str, failed: ErrorCode):
        self.node, self.what, self.failed = node, what, failed
        self.stopping = threading.Event()
        self.pool = WorkerPool(workers, waiting, name=name)
        self.processes = SynthesisProcesses(niceness=SERVER_CHILD_NICENESS, preload=preload)

    async def run(self, function, args=(), kwargs=None, size: str = '', arrival: float | None = None,
                  requested: float = 0.0):
        """``function(*args, **kwargs)`` in a child, awaited; raises StageStopped with the
        answer when the time or memory limit or shutdown ends it (``size`` says how large the
        request was, in the message; the time limit, the node's or the shorter ``requested``
        one when it is over 0, counts from ``arrival``, a time.monotonic() instant, or from now)."""
        timeout = self.node.get_parameter('timeout').value
        if requested > 0:
            timeout = min(timeout, requested)
        deadline = (time.monotonic() if arrival is None else arrival) + timeout
        try:
            return await self.pool.run(self._in_child, function, args, kwargs, deadline,
                                       wake=executor_waker(self.node),
                                       give_up=lambda: self.stopping.is_set() or time.monotonic() > deadline)
        except (Abandoned, SynthesisCancelledError):  # a timeout is a cancel by the deadline
            timed_out = not self.stopping.is_set()
            raise StageStopped(error_code(
                ErrorCode.TIMEOUT if timed_out else ErrorCode.PREEMPTED,
                f'{self.what} stopped: {"time limit" if timed_out else "shutdown"} ({timeout:g} s for {size})')) from None
        except SynthesisMemoryError as error:
            raise StageStopped(error_code(self.failed, f'{self.what} failed: {error} (memory_limit_mb, {size})')) from None

    def _in_child(self, function, args, kwargs, deadline: float):
        if self.stopping.is_set() or time.monotonic() > deadline:
            raise SynthesisCancelledError('stopped while waiting')
        return self.processes.call(function, args, kwargs, cancel=self.stopping, deadline=deadline,
                                   memory_limit=self.node.get_parameter('memory_limit_mb').value * 2**20)

    def stop(self) -> None:
        """Kill every child, busy or idle, and refuse further work (at shutdown)."""
        self.stopping.set()
        self.processes.close()
