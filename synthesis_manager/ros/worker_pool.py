"""Blocking work (a synthesis) run off the executor, awaited by async service callbacks.

A service callback that synthesizes for a minute must not hold an executor thread: with a
handful of them every thread is taken and cancel requests, other services and the action
server wait. The callback instead hands the work to this pool and awaits it; the pool runs
at most ``workers`` jobs at once, keeps up to ``max_waiting`` more in arrival order and
refuses the rest (:class:`~synthesis_manager.limits.BusyError`), so a burst is bounded.

Worker threads are daemons: a synthesis that ignored its cancel event could otherwise keep
the process alive after SIGTERM.
"""

from __future__ import annotations

import queue
import threading
from concurrent.futures import Future

from respec.vocabulary.errors import ControlFlowSignal
from synthesis_manager.limits import BusyError
from synthesis_manager.ros.stage_calls import WATCH_PERIOD, next_executor_turn


class Abandoned(ControlFlowSignal):
    """Control flow, not an error: the caller gave up on a job that had not started (see
    WorkerPool.run's ``give_up``); the caller answers its request itself."""


def executor_waker(node):
    """A ``wake`` for :meth:`WorkerPool.run`: wakes ``node``'s executor, once it has one, so the
    callback awaiting a finished job resumes at once instead of at the executor's next event."""
    def wake():
        executor = node.executor
        if executor is not None:
            executor.wake()
    return wake


class WorkerPool:
    def __init__(self, workers: int, max_waiting: int, name: str = 'worker'):
        if workers < 1 or max_waiting < 0:
            raise ValueError('a worker pool needs workers >= 1 and max_waiting >= 0')
        self.workers, self.max_waiting, self.name = workers, max_waiting, name
        self._jobs: queue.SimpleQueue = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self._outstanding = 0  # running + waiting

    @property
    def outstanding(self) -> int:
        with self._lock:
            return self._outstanding

    def submit(self, function, *args) -> Future:
        """Queue ``function(*args)``; raises BusyError when the pool is at its limit."""
        with self._lock:
            if self._outstanding >= self.workers + self.max_waiting:
                raise BusyError(f'{self._outstanding} jobs are running or waiting (limit '
                               f'{self.workers} running + {self.max_waiting} waiting); try again later',
                               self.name)
            self._outstanding += 1
            if len(self._threads) < min(self.workers, self._outstanding):
                thread = threading.Thread(target=self._work, name=f'{self.name}-{len(self._threads)}',
                                          daemon=True)
                self._threads.append(thread)
                thread.start()
        future: Future = Future()
        self._jobs.put((future, function, args))
        return future

    async def run(self, function, *args, wake=None, each_turn=None, give_up=None):
        """Await ``function(*args)`` from a coroutine; ``wake()`` is called when it is done
        (pass the executor's ``wake`` so the waiting callback resumes at once), ``each_turn()``
        each time the waiting coroutine resumes (e.g. to pass a cancel on to the job). When
        ``give_up()`` is true while the job still waits for a worker, it is dropped and
        Abandoned raised: a job past its deadline must not wait for a worker to say so."""
        future = self.submit(function, *args)
        if wake is not None:
            future.add_done_callback(lambda _: wake())
        while not future.done():
            if each_turn is not None:
                each_turn()
            if give_up is not None and give_up() and future.cancel():
                raise Abandoned()
            await next_executor_turn(future.done, WATCH_PERIOD)
        return future.result()

    def _work(self):
        while True:
            future, function, args = self._jobs.get()
            try:
                if future.set_running_or_notify_cancel():
                    future.set_result(function(*args))
            except BaseException as error:  # noqa: BLE001 - handed to the awaiting callback
                future.set_exception(error)
            finally:
                with self._lock:
                    self._outstanding -= 1
