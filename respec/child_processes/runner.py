"""Work in child processes that a cancel, a deadline or a shutdown ends at once.

Native code (CUDD, MuJoCo and its renderer) may run for seconds in one call, holding Python's
GIL: in the same process, nothing else runs meanwhile (not a cancel request, not a signal
handler). It may also crash or hold on to memory. So the work runs in a child process; the
caller waits in short polls and kills the child when the work must stop, so stopping takes
milliseconds whatever the child is doing, and the CPU and memory are released with the
process. Each child runs ``niceness`` below its parent's CPU priority.

    child = ChildProcess(preload='my.module', environment={'MUJOCO_GL': 'egl'})
    value = child.call(my.module.function, (settings,), cancel=event, deadline=deadline,
                       on_progress=print)   # function(settings, progress=...) reports as it goes
    child.kill()

A caller may also speak to the work while it runs: with ``wants_commands=True`` the function is
given ``commands=`` a callable that waits up to a timeout for what another thread of the caller
sent with ``child.command(value)`` and returns it as a list (the GUI's operator commands to a
running simulation). A command that arrives after the work ended is dropped.

``ChildProcesses`` is a pool of such children. Idle children are kept for the next call (a new
one costs the start of a Python interpreter, a fraction of a second), but not for long: a child
idle for ``idle_seconds`` is ended (its heap grows with what it did; after a burst of syntheses,
idle children held 2.6x the baseline RSS), and as many fresh ones as were prepared replace them.

    processes = ChildProcesses(preload='my.module')
    value = processes.call(function, args, kwargs, cancel=event, deadline=deadline, memory_limit=2**30)
    processes.close()

Functions are passed as themselves (picklable: defined at the top level of a module), so the
child imports what the caller already imports. Arguments and results travel as pickles; an
argument that is a :class:`BuiltInChild` is given to the function as what it builds in the
child; an exception raised in the child is raised in the caller. A child that dies (killed
from outside, crashed) raises :class:`ChildDiedError`; a cancel or the deadline raises
WorkCancelledError (WorkTimeoutError). Work that checks a memory limit of its own (a
synthesis) can say what it was doing when it stops; work that checks none is given
``memory_limit``: the caller watches the child's resident memory as it polls and kills it once
the work has grown it by more (WorkMemoryError). ``name`` is what messages call the children.
"""

from __future__ import annotations

import functools
import importlib
import io
import operator
import os
import pickle
import select
import subprocess
import sys
import threading
import time
import traceback
from typing import IO, Any, Callable, Protocol, cast

from respec.child_processes.errors import ChildDiedError, ChildWorkError, WorkCancelledError, WorkMemoryError, \
    WorkTimeoutError
from respec.child_processes.memory import released_memory, resident_memory



class CancelFlag(Protocol):
    """What stops work when it is set: a threading.Event, or a caller's own flag."""

    def is_set(self) -> bool: ...


# How often the caller looks at its cancel flag and deadline while a child works.
POLL_SECONDS = 0.02
# How long past its deadline a child may take to report its timeout before it is killed (its
# interrupt checks at least every few milliseconds, beyond one BDD operation).
DEADLINE_GRACE_SECONDS = 0.3
#: How much lower the children's CPU priority is than their parent's (by default).
CHILD_NICENESS = 5
#: The same for a server running many syntheses at once: eight CPU-bound children at +5 on two
#: cores outweighed their parent (it got under half a core), so its answers came late.
SERVER_CHILD_NICENESS = 15
#: Work that has run this long is long work: its child drops to the lowest CPU priority, so that
#: short work started beside it (another client's goal) is not slowed by it. Such a child is
#: not reused: without privileges its priority cannot be raised again.
LONG_WORK_SECONDS = 2.0
LOWEST_PRIORITY = 19
#: How long an idle child is kept for the next call.
IDLE_SECONDS = 30.0
#: What messages call a child process unless its caller names it.
CHILD_PROCESS = 'child process'
_LENGTH_BYTES = 8
#: Tags a message to the child that is a command to the running work, not a request.
_COMMAND = 'command'
#: A child that holds more than this above its fresh size after answering and releasing what
#: it answered (heap it could not give back) is ended, and a fresh one serves the next request:
#: a memory limit counts from a synthesis's start, so a reused child peaks within this of a
#: fresh one (a child holding its previous answer peaked at twice its limit, issue 34 item 4).
REUSE_MARGIN_BYTES = 64 * 2**20
#: Growth after an answer below which the child does not collect and trim its heap.
RELEASE_ABOVE_BYTES = 16 * 2**20
#: How long a child may take to release what it answered before it is ended instead of reused.
SETTLE_SECONDS = 5.0


class BuiltInChild:
    """An argument built where it is used: the caller sends it as it is (text, cheap to send),
    and the function in the child is given what :meth:`built` returns there (e.g. a large
    specification parsed in the child: parsing it in the caller would hold its interpreter)."""

    def built(self) -> object:
        raise NotImplementedError


class WorkingChildrenMemory:
    """The resident memory of this process and all its children (the tree), bounded while any
    child works.

    Each child's own limit (a synthesis' memory_limit) bounds one piece of work; eight at once
    could still hold eight times that. Past ``limit`` bytes in all, the working child holding
    the most is ended (WorkMemoryError naming the sum limit), so the others go on. Read at
    most every ``period`` seconds, whichever working child polls first; a tree that grew since
    the last reading is judged by where it will be at the next, so that it never passes the
    limit between two readings (a BDD bomb grows about 10 MiB in 0.1 s)."""

    def __init__(self, limit: int | None = None, period: float = 0.1):
        self.limit, self.period = limit, period
        self._working: set[ChildProcess] = set()
        self._lock = threading.Lock()
        self._read_at = -float('inf')
        self._over: ChildProcess | None = None
        self.total = 0  # bytes, at the last reading
        self.growth = 0  # bytes the tree grew between the last two readings (0 if it shrank)

    def working(self, child: ChildProcess, busy: bool) -> None:
        with self._lock:
            (self._working.add if busy else self._working.discard)(child)

    def is_over(self, child: ChildProcess) -> bool:
        """Whether ``child`` is the one to end: the working children exceed the limit together
        and it holds the most of them."""
        if self.limit is None:
            return False
        with self._lock:
            now = time.monotonic()
            if now - self._read_at >= self.period:
                recent = now - self._read_at < 2 * self.period  # growth over one period, not since long ago
                self._read_at = now
                sizes = {working: resident_memory(working.process.pid) for working in self._working}
                others = [pid for pid in _child_pids() if pid not in {w.process.pid for w in sizes}]
                total = sum(sizes.values()) + resident_memory() + sum(resident_memory(pid) for pid in others)
                self.growth, self.total = (max(0, total - self.total) if recent else 0), total
                self._over = max(sizes, key=sizes.__getitem__) if sizes and total + self.growth > self.limit else None
            return self._over is child


#: The sum limit of this process's tree (a server sets it: memory_sum_limit_mb).
WORKING_CHILDREN_MEMORY = WorkingChildrenMemory()


def _child_pids() -> list[int]:
    """This process's child processes (of every thread: each thread's children are its own)."""
    pids = []
    for task in os.scandir('/proc/self/task') if os.path.isdir('/proc/self/task') else ():
        try:
            with open(os.path.join(task.path, 'children')) as children:
                pids += [int(pid) for pid in children.read().split()]
        except OSError:  # the thread ended meanwhile
            continue
    return pids


class ChildProcess:
    """One child process (``python -m respec.child_processes.runner PARENT NICENESS PRELOAD
    NAME``), spoken to through its stdin and stdout: length-prefixed pickles, a request
    (function, args, kwargs, whether progress is wanted, whether commands are) in; ('progress',
    value) messages and then an answer ('result', value) or ('error', exception) out, then
    ('ready' or 'retire', bytes held) once the child has released the request and its answer
    (see :meth:`settle`). ``preload`` is imported at its start, so the first request need not
    wait for it; ``environment`` holds defaults for variables the parent's environment does not
    set; ``name`` is what messages call the process."""

    def __init__(self, niceness: int = 0, preload: str = '', environment: dict[str, str] | None = None,
                 name: str = CHILD_PROCESS):
        self.name = name
        self.idle_since = time.monotonic()
        self.fresh = True  # has served nothing yet: its RSS is the baseline
        self.said = 'ready'  # what it said after its last answer
        self.settling = False  # releasing its last request and answer: says 'ready' or 'retire' then
        self.demoted = False  # at the lowest CPU priority since long work: not reused
        self._writing = threading.Lock()  # a request and commands from other threads share stdin
        self.process = subprocess.Popen(
            [sys.executable, '-m', __name__, str(os.getpid()), str(niceness), preload, name],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            env={**environment, **os.environ} if environment else None)

    def call(self, function: Callable[..., Any], args: tuple[Any, ...] | list[Any] = (),
             kwargs: dict[str, Any] | None = None, cancel: CancelFlag | None = None,
             deadline: float | None = None, on_progress: Callable[[Any], None] | None = None,
             wants_commands: bool = False, memory_limit: int | None = None) -> Any:
        """``function(*args, **kwargs)`` in this child; with ``on_progress``, ``function`` is
        also given ``progress=`` a callable whose every value reaches ``on_progress`` here; with
        ``wants_commands``, ``commands=`` a callable ``(timeout) -> [value, ...]`` of what
        :meth:`command` sent meanwhile.
        The child is killed once ``cancel`` is set, at ``deadline`` (time.monotonic()) or once
        its resident memory has grown by more than ``memory_limit`` bytes since the call
        (WorkMemoryError, ``item`` 'memory_limit'); one that dies raises ChildDiedError."""
        try:
            if not self.settle() and self.said == 'nothing':  # its next words would be misread
                raise self.died()
            baseline = resident_memory(self.process.pid) if memory_limit is not None else 0
            long_work_at = time.monotonic() + LONG_WORK_SECONDS
            WORKING_CHILDREN_MEMORY.working(self, True)
            self.send((function, tuple(args), dict(kwargs or {}), on_progress is not None, wants_commands))
            while True:
                while not self.answered(POLL_SECONDS):
                    if WORKING_CHILDREN_MEMORY.is_over(self):
                        self.kill()
                        raise WorkMemoryError(
                            f'the work needed more memory than was left of the '
                            f'{(WORKING_CHILDREN_MEMORY.limit or 0) / 2**20:.0f} MB that all work at once may hold '
                            f'(memory_sum_limit_mb; it held the most of the {WORKING_CHILDREN_MEMORY.total / 2**20:.0f} MB '
                            'the server and its processes held)',
                            item='memory_sum_limit')
                    if cancel is not None and cancel.is_set():
                        self.kill()
                        raise WorkCancelledError('cancelled')
                    # Past the deadline the child has DEADLINE_GRACE_SECONDS to report its own
                    # timeout, which names what it was doing and how large the task was.
                    if deadline is not None and time.monotonic() >= deadline + DEADLINE_GRACE_SECONDS:
                        self.kill()
                        raise WorkTimeoutError()
                    if memory_limit is not None and resident_memory(self.process.pid) - baseline > memory_limit:
                        self.kill()
                        raise WorkMemoryError(
                            f'the work needed more than its memory limit of {memory_limit / 2**20:.0f} MB',
                            item='memory_limit')
                    if not self.alive():
                        raise self.died()
                    if not self.demoted and time.monotonic() >= long_work_at:
                        self.demote()
                kind, value = self.receive()
                if kind != 'progress':
                    break
                assert on_progress is not None  # the child reports progress only when asked to
                on_progress(value)
        except (EOFError, OSError, ValueError):  # the child died, or its pipes were closed
            raise self.died() from None
        finally:
            WORKING_CHILDREN_MEMORY.working(self, False)
        self.settling = True
        if kind == 'error':
            raise value
        return value

    def settle(self, timeout: float = SETTLE_SECONDS) -> bool:
        """Whether this child may serve another request: after each answer it releases the
        request and the answer and then says 'ready', or 'retire' when it still holds more than
        REUSE_MARGIN_BYTES above its fresh size (a child that says neither in ``timeout`` or
        died may not serve either)."""
        if self.settling:
            self.settling = False
            try:
                said = self.receive()[0] if self.answered(timeout) else 'nothing'
            except (EOFError, OSError, ValueError):
                said = 'nothing'
            self.said = said
        return self.said == 'ready' and self.alive()

    def died(self) -> ChildDiedError:
        self.kill()
        return ChildDiedError(f'the {self.name} ended (exit code {self.process.poll()}) without an answer',
                              item=self.name)

    def send(self, message: object) -> None:
        data = _dumps(message)
        with self._writing:
            requests = _pipe(self.process.stdin)
            requests.write(len(data).to_bytes(_LENGTH_BYTES, 'little') + data)
            requests.flush()

    def command(self, value: object) -> bool:
        """Send ``value`` to the work running in this child (from any thread); False when the
        child is gone. The work reads it through its ``commands`` callable."""
        try:
            self.send((_COMMAND, value))
            return True
        except (OSError, ValueError):  # the child died or its pipe was closed
            return False

    def answered(self, timeout: float) -> bool:
        return bool(select.select([_pipe(self.process.stdout)], [], [], timeout)[0])

    def receive(self) -> Any:
        # Unbuffered: the next message must stay in the pipe, where answered() looks for it.
        answers = _unbuffered(_pipe(self.process.stdout))
        return pickle.loads(_read_exactly(answers, int.from_bytes(_read_exactly(answers, _LENGTH_BYTES), 'little')))

    def alive(self) -> bool:
        return self.process.poll() is None

    def demote(self) -> None:
        """Drop the child to the lowest CPU priority (long work: LONG_WORK_SECONDS)."""
        self.demoted = True
        try:
            os.setpriority(os.PRIO_PROCESS, self.process.pid, LOWEST_PRIORITY)
        except OSError:  # already gone
            pass

    def kill(self) -> None:
        """End the child now (from any thread) and release its pipes."""
        if self.alive():
            self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stdout):
            try:
                _pipe(stream).close()
            except OSError:  # a request half-written to a killed child
                pass


def _pipe(stream: IO[bytes] | None) -> IO[bytes]:
    """A child's stdin or stdout (always piped: see ChildProcess)."""
    assert stream is not None
    return stream


def _unbuffered(stream: IO[bytes]) -> io.RawIOBase:
    """The raw stream under a buffered pipe."""
    return cast(io.RawIOBase, cast(io.BufferedReader, stream).raw)


def _read_exactly(stream: io.RawIOBase, size: int) -> bytes:
    data = bytearray()
    while len(data) < size:  # a raw pipe gives what has arrived
        chunk = stream.read(size - len(data))
        if not chunk:
            raise EOFError('the other end of the pipe closed it')
        data += chunk
    return bytes(data)


class ChildProcesses:
    """A pool of child processes, one per piece of work running at the same time, each
    ``niceness`` below its parent's CPU priority, each importing ``preload`` before its first
    request; ``name`` is what messages call them."""

    def __init__(self, idle_seconds: float = IDLE_SECONDS, niceness: int = CHILD_NICENESS, preload: str = '',
                 name: str = CHILD_PROCESS):
        self.idle_seconds, self.niceness, self.preload, self.name = idle_seconds, niceness, preload, name
        self._idle: list[ChildProcess] = []
        self._busy: set[ChildProcess] = set()
        self._lock = threading.Lock()
        self._closed = False
        self._prepared = 0
        self._wake_reaper = threading.Event()
        self._reaper: threading.Thread | None = None

    def _new_child(self) -> ChildProcess:
        return ChildProcess(self.niceness, self.preload, name=self.name)

    def prepare(self, count: int = 1) -> None:
        """Start ``count`` idle children now, so that the first calls need not wait; as many
        fresh ones replace idle children that are ended."""
        with self._lock:
            self._prepared = count
            while len(self._idle) < count and not self._closed:
                self._idle.append(self._new_child())

    @property
    def idle_count(self) -> int:
        with self._lock:
            return len(self._idle)

    def _release_idle(self) -> None:
        """The reaper thread: end children idle for idle_seconds (fresh prepared ones replace
        them), until the pool closes."""
        while not self._closed:
            with self._lock:
                now = time.monotonic()
                stale = [child for child in self._idle if now - child.idle_since >= self.idle_seconds
                         and not child.fresh]
                self._idle = [child for child in self._idle if child not in stale]
                replacements = min(len(stale), self._prepared - len(self._idle))
                self._idle += [self._new_child() for _ in range(replacements)]
                next_check = min((child.idle_since + self.idle_seconds for child in self._idle
                                  if not child.fresh), default=None)
            for child in stale:
                child.kill()
            self._wake_reaper.wait(None if next_check is None else max(0.05, next_check - time.monotonic()))
            self._wake_reaper.clear()

    def call(self, function: Callable[..., Any], args: tuple[Any, ...] | list[Any] = (),
             kwargs: dict[str, Any] | None = None, cancel: CancelFlag | None = None,
             deadline: float | None = None, memory_limit: int | None = None) -> Any:
        """``function(*args, **kwargs)`` in a child (:meth:`ChildProcess.call`)."""
        child = self._take()
        try:
            return child.call(function, args, kwargs, cancel, deadline, memory_limit=memory_limit)
        except ChildDiedError:
            if self._closed:  # close() killed it
                raise WorkCancelledError('cancelled') from None
            raise
        finally:
            self._give_back(child, reusable=child.alive() and not child.demoted)  # stopped children were killed

    def close(self) -> None:
        """Kill every child, busy or idle (at shutdown)."""
        with self._lock:
            self._closed = True
            self._wake_reaper.set()
            children = self._idle + list(self._busy)
            self._idle, self._busy = [], set()
        for child in children:
            child.kill()

    def _take(self) -> ChildProcess:
        with self._lock:
            if self._closed:
                raise WorkCancelledError('cancelled')
            child = self._idle.pop() if self._idle else None
        if child is None or not child.settle():
            if child is not None:
                child.kill()
            child = self._new_child()
        with self._lock:
            if not self._closed:
                self._busy.add(child)
                return child
        child.kill()  # close() came while this child was readied, out of its sight: it would outlive the pool
        raise WorkCancelledError('cancelled')

    def _give_back(self, child: ChildProcess, reusable: bool) -> None:
        with self._lock:
            self._busy.discard(child)
            keep = reusable and not self._closed
            if keep:
                child.idle_since, child.fresh = time.monotonic(), False
                self._idle.append(child)
                if self._reaper is None:
                    self._reaper = threading.Thread(target=self._release_idle, name='child-process-reaper',
                                                    daemon=True)
                    self._reaper.start()
                self._wake_reaper.set()
            elif not self._closed and not self._idle:
                # A replacement starts now, while the caller reports the stop.
                self._idle.append(self._new_child())
        if not keep:
            child.kill()


def serve(parent_pid: int, preload: str, name: str) -> None:
    """The child: answer requests until stdin closes or the parent is gone."""
    _die_with_parent(parent_pid)
    # Unbuffered: a command must stay in the pipe, where select() sees it, until it is read.
    requests = _unbuffered(sys.stdin.buffer)
    answers = os.fdopen(os.dup(sys.stdout.fileno()), 'wb')
    sys.stdout = sys.stderr  # stray prints must not corrupt the answers
    if preload:
        importlib.import_module(preload)  # imported now: the first request need not wait for it
    fresh = released_memory()

    def send(message: object) -> None:
        data = _pickled(message, name)
        answers.write(len(data).to_bytes(_LENGTH_BYTES, 'little') + data)
        answers.flush()

    def read() -> Any:
        return pickle.loads(_read_exactly(requests, int.from_bytes(_read_exactly(requests, _LENGTH_BYTES), 'little')))

    def commands(timeout: float = 0.0) -> list[Any]:
        """What the caller sent to the running work (waiting up to ``timeout`` for it)."""
        received: list[Any] = []
        while select.select([requests], [], [], 0.0 if received else timeout)[0]:
            message = read()  # EOFError: the caller is gone; the work ends with it
            if message[0] == _COMMAND:
                received.append(message[1])
        return received

    while True:
        try:
            message = read()
        except EOFError:
            return
        if message[0] == _COMMAND:  # sent after its work ended
            continue
        function, args, kwargs, wants_progress, wants_commands = message
        if wants_progress:
            kwargs['progress'] = lambda value: send(('progress', value))
        if wants_commands:
            kwargs['commands'] = commands
        try:
            args = [argument.built() if isinstance(argument, BuiltInChild) else argument for argument in args]
            answer = ('result', function(*args, **kwargs))
        except Exception as error:  # noqa: BLE001 -- every failure goes back to the caller
            error.add_note(f'in the {name}:\n{traceback.format_exc()}')
            answer = ('error', error)
        send(answer)
        # The request and its answer (an error's traceback holds the whole solver) are released
        # before the next request is read (after answering: freeing them takes time), so that
        # its memory limit counts from what the child really holds.
        del function, args, kwargs, answer
        held = resident_memory() - fresh
        if held > RELEASE_ABOVE_BYTES:  # a collection and a trim take 20-30 ms: only when it pays
            held = released_memory() - fresh
        # 'retire': the parent ends this child, a fresh one serves the next request.
        send(('retire' if held > REUSE_MARGIN_BYTES else 'ready', held))


def _dumps(message: object) -> bytes:
    """``message`` pickled, formula nodes as their class and fields: through the dataclasses'
    own pickling (which looks up their fields at every node), a tiny gridworld's specification
    took 3.5 ms to pickle and 2.7 ms to load, 0.75 and 0.7 ms this way (the same objects, shared
    subformulas still shared)."""
    stream = io.BytesIO()
    pickler = pickle.Pickler(stream, protocol=pickle.HIGHEST_PROTOCOL)
    pickler.dispatch_table = _formula_dispatch_table()
    pickler.dump(message)
    return stream.getvalue()


@functools.cache
def _formula_dispatch_table() -> dict[type, Callable[[Any], Any]]:
    import copyreg
    import dataclasses
    from respec import ltl
    table: dict[type, Callable[[Any], Any]] = dict(copyreg.dispatch_table)
    for kind in (ltl.Const, ltl.Var, ltl.Not, ltl.And, ltl.Or, ltl.Implies, ltl.Iff, ltl.Next):
        table[kind] = _fields_reducer(kind, [field.name for field in dataclasses.fields(kind)])
    return table


def _fields_reducer(kind: type, names: list[str]) -> Callable[[Any], tuple[Any, ...]]:
    """A pickle reducer of ``kind``: rebuilt as ``kind(*fields)``."""
    if len(names) == 1:
        read_one = operator.attrgetter(names[0])
        return lambda node: (kind, (read_one(node),))
    read = operator.attrgetter(*names)
    return lambda node: (kind, read(node))


def _pickled(message: object, name: str) -> bytes:
    try:
        return _dumps(message)
    except Exception as error:  # noqa: BLE001 -- e.g. an exception that cannot be pickled
        return pickle.dumps(('error', ChildWorkError(f'{name}: {error!r}')))


def _die_with_parent(parent_pid: int) -> None:
    """A child whose parent was killed (with no chance to stop it) ends too, within half a second.

    Not the kernel's parent-death signal (PR_SET_PDEATHSIG): it fires when the parent *thread*
    that started the child ends, and children are started from worker threads that come and go.
    """
    if os.getppid() != parent_pid:  # the parent died before the child got here
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


if __name__ == '__main__':
    # Below the parent's priority: work filling every core must not delay the parent's answers
    # (time limits, cancels, BUSY) on a loaded machine.
    os.nice(int(sys.argv[2]))
    from respec.nesting import run_with_deep_stack
    # The imported copy of this module serves, not this __main__ one: the classes it checks
    # (BuiltInChild) and sends (ChildWorkError) are the ones the parent's requests name.
    serve = importlib.import_module('respec.child_processes.runner').serve
    # Requests are served in a thread with room for any formula accepted (pickles of formula
    # trees are read and written recursively).
    run_with_deep_stack(serve, int(sys.argv[1]), sys.argv[3], sys.argv[4])
