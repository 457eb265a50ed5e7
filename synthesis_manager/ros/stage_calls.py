"""Pipeline service calls awaited from async execute callbacks, watched while they run.

A goal's execute callback is a coroutine: while a stage's service works, it awaits instead
of holding an executor thread, so any number of goals can wait side by side and the
executor keeps serving (with blocking waits, 8 waiting goals on an 8-thread executor starved
the very services they waited for). Each wait ends with the response, or as soon as one of
these happens (checked at least every WATCH_PERIOD seconds):

- the client cancels the goal              -> Preempted
- the stage's time limit passes            -> StageTimeoutError (TIMEOUT)
- the server shuts down                    -> ServerStoppingError (BEHAVIOR_SYNTHESIS_FAILED)
- the node serving the stage goes away     -> StageUnavailableError (SERVICE_UNAVAILABLE) naming it
  (also when a new node took its place: the request went to the one that left; looked at
  every READER_CHECK_PERIOD seconds, graph queries being the dearest of these checks)

How the waiting works: rclpy's executor resumes every pending coroutine each time it wakes,
and a timer wakes it every WATCH_PERIOD seconds while calls wait (LookTimer); a coroutine waits by
yielding once (:func:`next_executor_turn`) and then checks its conditions again. The turn says
when resuming is worth it (its response arrived, or its next look is due): the suite's executor
(ros/executor.py) leaves a coroutine whose turn is not due suspended, because with hundreds of
waiting goals resuming each of them on every wake-up took the spinning thread most of its time
and new goals waited seconds to be accepted. Any other executor just resumes it every time.
"""

from __future__ import annotations

import contextlib
import threading
import time
from typing import Callable

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup

from respec.vocabulary.errors import CodedError, ControlFlowSignal, ErrorCode

WATCH_PERIOD = 0.1
READER_CHECK_PERIOD = 0.5  # seconds between two looks at whether a pending request's node is there


class StageFailedError(CodedError):
    """A pipeline service answered with an error code: the goal ends with that answer, relayed.
    The one error whose code is per instance (it is the stage's); an answer whose number this
    suite does not know keeps the class's code and names the number."""

    code = ErrorCode.BEHAVIOR_SYNTHESIS_FAILED

    def __init__(self, answer):
        try:
            self.code = ErrorCode.from_number(answer.value)
        except ValueError:
            super().__init__(f'a stage answered the unknown error code {answer.value}: {answer.message}',
                             answer.value)
        else:
            super().__init__(answer.message or self.code.name)


class StageUnavailableError(CodedError):
    """A pipeline service is not there, or its node went away while working."""

    code = ErrorCode.SERVICE_UNAVAILABLE


class StageTimeoutError(CodedError):
    """A pipeline service did not answer in time."""

    code = ErrorCode.TIMEOUT


class ServerStoppingError(CodedError):
    """The server shuts down while a goal waits on a stage."""

    code = ErrorCode.BEHAVIOR_SYNTHESIS_FAILED


class Preempted(ControlFlowSignal):
    """Control flow, not an error: the client cancelled the goal while it waited on a stage
    (the goal then ends cancelled, with PREEMPTED)."""


class ExecutorTurn:
    """Awaitable: gives the executor back once (its own iterator, so that an executor finds it
    as the innermost ``cr_await`` of the suspended coroutine and can ask :meth:`due`)."""

    __slots__ = ('_due', '_given')

    def __init__(self, due: Callable[[], bool] | None = None):
        self._due, self._given = due, False

    def due(self) -> bool:
        """Whether the waiting coroutine has something to look at if resumed now."""
        return self._due is None or self._due()

    def __await__(self):
        return self

    def __iter__(self):
        return self

    def __next__(self):
        if self._given:
            raise StopIteration
        self._given = True


def next_executor_turn(ready: Callable[[], bool] | None = None, look_every: float | None = None) -> ExecutorTurn:
    """Awaitable: give the executor back until it next wakes (a response, a timer tick...).

    With ``ready`` (e.g. a future's ``done``) or ``look_every`` (seconds), resuming is only due
    once ``ready()`` is true or that time has passed (to check cancel, deadlines, the node)."""
    if ready is None and look_every is None:
        return ExecutorTurn()
    look_at = time.monotonic() + look_every if look_every is not None else float('inf')
    if ready is None:
        return ExecutorTurn(lambda: time.monotonic() >= look_at)
    return ExecutorTurn(lambda: ready() or time.monotonic() >= look_at)


def awaited_turn(coroutine) -> ExecutorTurn | None:
    """The ExecutorTurn a suspended coroutine waits on, through nested awaits; None when it
    waits on anything else."""
    awaited = coroutine
    while awaited is not None and not isinstance(awaited, ExecutorTurn):
        awaited = getattr(awaited, 'cr_await', None)
    return awaited


class LookTimer:
    """A timer of ``node`` waking its executor every ``period`` seconds while at least one
    coroutine waits inside :meth:`waiting` (so that it takes its looks at cancel, deadlines and
    the node), and off otherwise: an idle suite wakes for nothing (ten wake-ups a second per
    timer cost an idle ``serve`` about 1.5 % of a core each).

    Only the timer's own callback turns it off, one period after the last waiter left: rclpy
    fails a timer cancelled by another thread between the executor finding it due and calling it.
    """

    def __init__(self, node, period: float = WATCH_PERIOD):
        self._node = node
        self._waiting = 0
        self._lock = threading.Lock()
        # Its own mutually exclusive group: the executor never takes it while its callback runs.
        self._timer = node.create_timer(period, self._tick, callback_group=MutuallyExclusiveCallbackGroup())
        self._timer.cancel()

    @property
    def active(self) -> bool:
        return not self._timer.is_canceled()

    @contextlib.contextmanager
    def waiting(self):
        with self._lock:
            self._waiting += 1
            if self._timer.is_canceled():
                self._timer.reset()
                # The executor may be waiting on a wait set built while the timer was off.
                executor = self._node.executor
                if executor is not None:
                    executor.wake()
        try:
            yield
        finally:
            with self._lock:
                self._waiting -= 1

    def _tick(self):
        with self._lock:
            if not self._waiting:
                self._timer.cancel()


class StageCaller:
    """Makes watched service calls for ``node``'s coroutines (see the module docstring)."""

    def __init__(self, node, watch_period: float = WATCH_PERIOD):
        self.node = node
        self.watch_period = watch_period
        self._stopping = threading.Event()
        self._providers: dict[str, str] = {}
        # Wakes the executor while calls wait; the waiting coroutines do the checking.
        self.looks = LookTimer(node, watch_period)

    def stop(self):
        """Make every waiting call give up (at shutdown)."""
        self._stopping.set()

    async def call(self, client, request, stage: str, timeout: float, service_timeout: float,
                   cancelled: Callable[[], bool] = lambda: False, on_cancel: Callable[[], None] | None = None):
        """``client``'s response to ``request``, or one of the exceptions above."""
        with self.looks.waiting():
            return await self._call(client, request, stage, timeout, service_timeout, cancelled, on_cancel)

    async def _call(self, client, request, stage, timeout, service_timeout, cancelled, on_cancel):
        await self._wait_for_service(client, stage, service_timeout, cancelled)
        provider = self._providers.get(client.srv_name) or self._find_provider(client.srv_name)
        readers = self._request_readers(client.srv_name)
        future = client.call_async(request)
        deadline = time.monotonic() + timeout
        next_reader_check = time.monotonic() + READER_CHECK_PERIOD
        while not future.done():
            failure = None
            now = time.monotonic()
            if self._stopping.is_set():
                failure = ServerStoppingError(f'{stage}: the server is shutting down', stage)
            elif cancelled():
                failure = Preempted()
            elif now > deadline:
                failure = StageTimeoutError(f'{stage}: no answer from {client.srv_name!r} within {timeout:g} s',
                                        client.srv_name)
            elif now >= next_reader_check and not (client.service_is_ready() and (
                    not readers or readers & self._request_readers(client.srv_name))):
                self._providers.pop(client.srv_name, None)
                failure = StageUnavailableError(f'{stage}: node {provider!r} (service '
                                           f'{self.node.resolve_service_name(client.srv_name)!r}) went '
                                           'away before answering', provider)
            if now >= next_reader_check:
                next_reader_check = now + READER_CHECK_PERIOD
            if failure is not None:
                client.remove_pending_request(future)
                if on_cancel is not None and getattr(failure, 'code', None) != ErrorCode.SERVICE_UNAVAILABLE:
                    on_cancel()  # tell the service to stop working for nobody
                raise failure
            await next_executor_turn(future.done, min(self.watch_period, max(0.0, deadline - now)))
        return future.result()

    async def _wait_for_service(self, client, stage: str, service_timeout: float, cancelled):
        deadline = time.monotonic() + service_timeout
        while not client.service_is_ready():
            if self._stopping.is_set():
                raise ServerStoppingError(f'{stage}: the server is shutting down', stage)
            if cancelled():
                raise Preempted()
            if time.monotonic() > deadline:
                raise StageUnavailableError(f'{stage}: service {client.srv_name!r} is not available '
                                       f'(waited {service_timeout:g} s)', client.srv_name)
            await next_executor_turn(look_every=self.watch_period)

    def _request_readers(self, service_name: str) -> set[bytes]:
        """The endpoints that receive ``service_name``'s requests now (DDS reader ids).

        A node that died and was started again at once (a restarted host) offers the service
        again before its old self's lease ends, so the service never looks unavailable; but the
        request went to the old one, which will never answer. When none of the readers a
        request was sent to is left, its answer cannot come. (Several servers of one name: each
        got the request, and any one left may still answer.)
        """
        topic = f'rq{self.node.resolve_service_name(service_name)}Request'  # rmw_fastrtps's request topic
        return {bytes(info.endpoint_gid) for info in self.node.get_subscriptions_info_by_topic(topic, no_mangle=True)}

    def _find_provider(self, service_name: str) -> str:
        """The full name of the node serving ``service_name`` (remembered until it goes away)."""
        resolved = self.node.resolve_service_name(service_name)
        for name, namespace in self.node.get_node_names_and_namespaces():
            try:
                services = self.node.get_service_names_and_types_by_node(name, namespace)
            except Exception:  # noqa: BLE001 - the node left the graph meanwhile
                continue
            if any(service == resolved for service, _ in services):
                full_name = f'{namespace.rstrip("/")}/{name}'
                self._providers[service_name] = full_name
                return full_name
        return resolved
