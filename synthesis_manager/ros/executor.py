"""The executor every entry point spins its nodes on: rclpy's MultiThreadedExecutor, with
suspended coroutines resumed in the spinning thread.

rclpy (Jazzy) resumes every pending coroutine callback on each wake-up of the executor, and
MultiThreadedExecutor hands each resumption to its thread pool. The suite's waiting goals
and queued syntheses are such coroutines (they wait by yielding, see ros/stage_calls.py):
with 50 of them, every pass was 50 hand-offs between threads contending for the GIL, 20-80 ms
on a loaded 2-core machine, and a goal's answer needs several passes (the synthesis node
answers, the server takes the response, resumes the goal, sends the result). A resumption
only checks a few conditions and yields again, so it runs inline here; callbacks starting
(a service request, a timer, a goal's first run) still go to the pool, so blocking work
never holds the spinning thread. A coroutine waiting on an ExecutorTurn that is not due yet
(ros/stage_calls.py: no response, no look due) is not even resumed: with 200 goals waiting,
resuming all of them on every wake-up took 3.5 s of the spinning thread in an 8 s burst
(15,480 resumptions, 0.23 ms each) and goals were accepted up to 6 s after they were sent.
"""

from __future__ import annotations

import inspect

from rclpy.executors import (ConditionReachedException, ExternalShutdownException, MultiThreadedExecutor,
                             ShutdownException, TimeoutException)

from synthesis_manager.ros.stage_calls import awaited_turn


class SuiteExecutor(MultiThreadedExecutor):
    """MultiThreadedExecutor resuming suspended coroutine callbacks inline (module docstring)."""

    def _spin_once_impl(self, timeout_sec=None, wait_condition=lambda: False) -> None:
        try:
            handler, _, _ = self.wait_for_ready_callbacks(timeout_sec, None, wait_condition)
        except (ExternalShutdownException, ShutdownException, TimeoutException, ConditionReachedException):
            return
        if _suspended(handler):
            turn = awaited_turn(handler._handler)  # noqa: SLF001 - rclpy keeps the coroutine in the handler
            if turn is not None and not turn.due():
                return  # nothing for it to look at yet; the executor offers it again next pass
            handler()  # resumes, checks its conditions, and yields again or ends
            if not handler.done():
                return
        else:
            self._executor.submit(handler)
        self._futures.append(handler)
        for future in self._futures[:]:
            if future.done():
                self._futures.remove(future)
                future.result()  # raise any exceptions


def _suspended(task) -> bool:
    """Whether ``task`` is a coroutine that has run and waits at an ``await``."""
    coroutine = getattr(task, '_handler', None)  # rclpy's Task keeps its coroutine there
    return inspect.iscoroutine(coroutine) and inspect.getcoroutinestate(coroutine) == inspect.CORO_SUSPENDED
