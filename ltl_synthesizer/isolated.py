"""Work in child processes that a cancel, a deadline or a shutdown ends at once: the one
process runner of the project (syntheses, diagnoses, the GUI's simulations).

The synthesizer checks its limits between BDD operations, but one CUDD operation on a large
specification can run for seconds, holding Python's GIL: in the same process, nothing else
runs meanwhile (not a cancel request, not a signal handler). Native code (CUDD, MuJoCo and its
renderer) may also crash or hold on to memory. So the work runs in a child process; the
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

``SynthesisProcesses`` is a pool of such children for syntheses and other solver work. Idle
children are kept for the next call (a new one costs the start of a Python interpreter, a
fraction of a second), but not for long: a child idle for ``idle_seconds`` is ended (its heap
grows with what it solved; after a burst, idle children held 2.6x the baseline RSS), and as
many fresh ones as were prepared replace them.

    processes = SynthesisProcesses()
    result = processes.synthesize(spec, limits=Limits(cancel=event, deadline=time.monotonic() + 60))
    value = processes.call(function, args, kwargs, cancel=event, deadline=deadline)
    processes.close()

Functions are passed as themselves (picklable: defined at the top level of a module), so the
child imports what the caller already imports. Arguments and results travel as pickles; an
exception raised in the child is raised in the caller. A child that dies (killed from outside,
crashed) raises :class:`SynthesisProcessDiedError`; a cancel or the deadline raises
SynthesisCancelledError (SynthesisTimeoutError). A synthesis's memory limit is its own
(``ltl_synthesizer.Limits``, checked in the child, which can say what it was doing); work that
checks no limit of its own (compilation, state-machine generation) is given ``memory_limit``:
the caller watches the child's resident memory as it polls and kills it once the work has
grown it by more (SynthesisMemoryError).
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
from typing import Callable

from ltl_synthesizer.errors import SynthesisCancelledError, SynthesisError, SynthesisMemoryError, SynthesisTimeoutError
from ltl_synthesizer.interrupt import Limits, released_memory, resident_memory

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
#: How long an idle child is kept for the next synthesis.
IDLE_SECONDS = 30.0
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


class SynthesisProcessDiedError(SynthesisError):
    """The process running the synthesis ended without an answer."""


class SpecificationText:
    """A specification as its text sections, parsed where it is used: in the child (passed as
    an argument, the child gives the function the parsed GR1Specification). Parsing, printing
    and pickling a large specification take seconds of pure Python: done in the caller, they
    hold its interpreter, uninterruptible (a 3.9 MB one, about 9 s)."""

    def __init__(self, sections: dict):
        self.sections = sections

    def parsed(self):
        from respec.parsing import spec_from_text_sections
        return spec_from_text_sections(self.sections)


def byproduct_texts(spec) -> tuple[str, str, list, list]:
    """The ``.structuredslugs`` and ``.slugsin`` texts of ``spec``, and its inputs and outputs."""
    return spec.to_structuredslugs(), spec.to_slugsin(), list(spec.env_props), list(spec.sys_props)


def synthesize_within(spec, robotics_semantics: bool, limits: Limits, options, max_strategy_edges: int):
    """:func:`ltl_synthesizer.synthesize`, refusing (StrategyTooLargeError) a strategy of more
    than ``max_strategy_edges`` edges as soon as its extraction passes them, before anything is
    sent: each edge costs the receiving server about 900 B once turned into an automaton, its
    byproduct and its messages (a 215-byte specification with 11 free inputs has 8.4 M edges and
    grew a server to 7.7 GB; counted only after extraction, it took minutes in the child)."""
    from ltl_synthesizer.synthesizer import synthesize
    return synthesize(spec, robotics_semantics, limits, options, max_edges=max_strategy_edges)


#: What the pool's children import before their first request.
SYNTHESIZER_MODULE = 'ltl_synthesizer.synthesizer'


class WorkingChildrenMemory:
    """The resident memory of this process and all its children (the tree), bounded while any
    child works.

    Each child's own limit (a synthesis' memory_limit) bounds one piece of work; eight at once
    could still hold eight times that. Past ``limit`` bytes in all, the working child holding
    the most is ended (SynthesisMemoryError naming the sum limit), so the others go on. Read at
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
                self._over = max(sizes, key=sizes.get) if sizes and total + self.growth > self.limit else None
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
    """One child process (``python -m ltl_synthesizer.isolated PARENT NICENESS PRELOAD``),
    spoken to through its stdin and stdout: length-prefixed pickles, a request (function,
    args, kwargs, whether progress is wanted) in; ('progress', value) messages and then an
    answer ('result', value) or ('error', exception) out, then ('ready' or 'retire', bytes
    held) once the child has released the request and its answer (see :meth:`settle`). ``preload`` is imported at its start,
    so the first request need not wait for it; ``environment`` holds defaults for variables
    the parent's environment does not set."""

    def __init__(self, niceness: int = 0, preload: str = SYNTHESIZER_MODULE,
                 environment: dict[str, str] | None = None):
        self.idle_since = time.monotonic()
        self.fresh = True  # has served nothing yet: its RSS is the baseline
        self.said = 'ready'  # what it said after its last answer
        self.settling = False  # releasing its last request and answer: says 'ready' or 'retire' then
        self.demoted = False  # at the lowest CPU priority since long work: not reused
        self._writing = threading.Lock()  # a request and commands from other threads share stdin
        self.process = subprocess.Popen(
            [sys.executable, '-m', 'ltl_synthesizer.isolated', str(os.getpid()), str(niceness), preload],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            env={**environment, **os.environ} if environment else None)

    def call(self, function: Callable, args=(), kwargs=None, cancel: threading.Event | None = None,
             deadline: float | None = None, on_progress: Callable | None = None, wants_commands: bool = False,
             memory_limit: int | None = None):
        """``function(*args, **kwargs)`` in this child; with ``on_progress``, ``function`` is
        also given ``progress=`` a callable whose every value reaches ``on_progress`` here; with
        ``wants_commands``, ``commands=`` a callable ``(timeout) -> [value, ...]`` of what
        :meth:`command` sent meanwhile.
        The child is killed once ``cancel`` is set, at ``deadline`` (time.monotonic()) or once
        its resident memory has grown by more than ``memory_limit`` bytes since the call
        (SynthesisMemoryError, ``item`` 'memory_limit'); one that dies raises
        SynthesisProcessDiedError."""
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
                        raise SynthesisMemoryError(
                            f'the work needed more memory than was left of the '
                            f'{WORKING_CHILDREN_MEMORY.limit / 2**20:.0f} MB that all work at once may hold '
                            f'(memory_sum_limit_mb; it held the most of the {WORKING_CHILDREN_MEMORY.total / 2**20:.0f} MB '
                            'the server and its processes held)',
                            item='memory_sum_limit')
                    if cancel is not None and cancel.is_set():
                        self.kill()
                        raise SynthesisCancelledError('cancelled')
                    # Past the deadline the child has DEADLINE_GRACE_SECONDS to report its own
                    # timeout, which names what it was doing and how large the task was.
                    if deadline is not None and time.monotonic() >= deadline + DEADLINE_GRACE_SECONDS:
                        self.kill()
                        raise SynthesisTimeoutError()
                    if memory_limit is not None and resident_memory(self.process.pid) - baseline > memory_limit:
                        self.kill()
                        raise SynthesisMemoryError(
                            f'the work needed more than its memory limit of {memory_limit / 2**20:.0f} MB',
                            item='memory_limit')
                    if not self.alive():
                        raise self.died()
                    if not self.demoted and time.monotonic() >= long_work_at:
                        self.demote()
                kind, value = self.receive()
                if kind != 'progress':
                    break
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

    def died(self) -> SynthesisProcessDiedError:
        self.kill()
        return SynthesisProcessDiedError(f'the synthesis process ended (exit code {self.process.poll()}) '
                                         'without an answer', item='synthesis process')

    def send(self, message) -> None:
        data = _dumps(message)
        with self._writing:
            self.process.stdin.write(len(data).to_bytes(_LENGTH_BYTES, 'little') + data)
            self.process.stdin.flush()

    def command(self, value) -> bool:
        """Send ``value`` to the work running in this child (from any thread); False when the
        child is gone. The work reads it through its ``commands`` callable."""
        try:
            self.send((_COMMAND, value))
            return True
        except (OSError, ValueError):  # the child died or its pipe was closed
            return False

    def answered(self, timeout: float) -> bool:
        return bool(select.select([self.process.stdout], [], [], timeout)[0])

    def receive(self):
        # Unbuffered: the next message must stay in the pipe, where answered() looks for it.
        answers = self.process.stdout.raw
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
                stream.close()
            except OSError:  # a request half-written to a killed child
                pass


def _read_exactly(stream, size: int) -> bytes:
    data = bytearray()
    while len(data) < size:  # a raw pipe gives what has arrived
        chunk = stream.read(size - len(data))
        if not chunk:
            raise EOFError('the synthesis process closed its output')
        data += chunk
    return bytes(data)


class SynthesisProcesses:
    """A pool of synthesis child processes, one per synthesis running at the same time, each
    ``niceness`` below its parent's CPU priority."""

    def __init__(self, idle_seconds: float = IDLE_SECONDS, niceness: int = CHILD_NICENESS,
                 preload: str = SYNTHESIZER_MODULE):
        """``preload``: what the children import before their first request."""
        self.idle_seconds, self.niceness, self.preload = idle_seconds, niceness, preload
        self._idle: list[ChildProcess] = []
        self._busy: set[ChildProcess] = set()
        self._lock = threading.Lock()
        self._closed = False
        self._prepared = 0
        self._wake_reaper = threading.Event()
        self._reaper: threading.Thread | None = None

    def prepare(self, count: int = 1) -> None:
        """Start ``count`` idle children now, so that the first syntheses need not wait; as
        many fresh ones replace idle children that are ended."""
        with self._lock:
            self._prepared = count
            while len(self._idle) < count and not self._closed:
                self._idle.append(ChildProcess(self.niceness, self.preload))

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
                self._idle += [ChildProcess(self.niceness, self.preload) for _ in range(replacements)]
                next_check = min((child.idle_since + self.idle_seconds for child in self._idle
                                  if not child.fresh), default=None)
            for child in stale:
                child.kill()
            self._wake_reaper.wait(None if next_check is None else max(0.05, next_check - time.monotonic()))
            self._wake_reaper.clear()

    def synthesize(self, spec, robotics_semantics: bool = True, limits: Limits = Limits(), options=None,
                   max_strategy_edges: int | None = None):
        """:func:`ltl_synthesizer.synthesize` in a child, killed once ``limits`` stop it; with
        ``max_strategy_edges``, a larger strategy is refused in the child (:func:`synthesize_within`)."""
        from ltl_synthesizer.synthesizer import synthesize
        if max_strategy_edges:
            return self.call(synthesize_within, (spec, robotics_semantics, limits.without_cancel(), options,
                                                 max_strategy_edges), cancel=limits.cancel, deadline=limits.deadline)
        return self.call(synthesize, (spec, robotics_semantics, limits.without_cancel(), options),
                         cancel=limits.cancel, deadline=limits.deadline)

    def call(self, function: Callable, args=(), kwargs=None, cancel: threading.Event | None = None,
             deadline: float | None = None, memory_limit: int | None = None):
        """``function(*args, **kwargs)`` in a child (:meth:`ChildProcess.call`)."""
        child = self._take()
        try:
            return child.call(function, args, kwargs, cancel, deadline, memory_limit=memory_limit)
        except SynthesisProcessDiedError:
            if self._closed:  # close() killed it
                raise SynthesisCancelledError('cancelled') from None
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
                raise SynthesisCancelledError('cancelled')
            child = self._idle.pop() if self._idle else None
        if child is None or not child.settle():
            if child is not None:
                child.kill()
            child = ChildProcess(self.niceness, self.preload)
        with self._lock:
            self._busy.add(child)
        return child

    def _give_back(self, child: ChildProcess, reusable: bool) -> None:
        with self._lock:
            self._busy.discard(child)
            keep = reusable and not self._closed
            if keep:
                child.idle_since, child.fresh = time.monotonic(), False
                self._idle.append(child)
                if self._reaper is None:
                    self._reaper = threading.Thread(target=self._release_idle, name='synthesis-process-reaper',
                                                    daemon=True)
                    self._reaper.start()
                self._wake_reaper.set()
            elif not self._closed and not self._idle:
                # A replacement starts now, while the caller reports the stop.
                self._idle.append(ChildProcess(self.niceness, self.preload))
        if not keep:
            child.kill()


def _serve(parent_pid: int, preload: str) -> None:
    """The child: answer requests until stdin closes or the parent is gone."""
    # This module runs as __main__ here: requests name the class of its imported copy.
    text_type = importlib.import_module('ltl_synthesizer.isolated').SpecificationText
    _die_with_parent(parent_pid)
    # Unbuffered: a command must stay in the pipe, where select() sees it, until it is read.
    requests = sys.stdin.buffer.raw
    answers = os.fdopen(os.dup(sys.stdout.fileno()), 'wb')
    sys.stdout = sys.stderr  # stray prints must not corrupt the answers
    importlib.import_module(preload)  # imported now: the first request need not wait for it
    fresh = released_memory()

    def send(message) -> None:
        data = _pickled(message)
        answers.write(len(data).to_bytes(_LENGTH_BYTES, 'little') + data)
        answers.flush()

    def read():
        return pickle.loads(_read_exactly(requests, int.from_bytes(_read_exactly(requests, _LENGTH_BYTES), 'little')))

    def commands(timeout: float = 0.0) -> list:
        """What the caller sent to the running work (waiting up to ``timeout`` for it)."""
        received = []
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
            args = [argument.parsed() if isinstance(argument, text_type) else argument for argument in args]
            answer = ('result', function(*args, **kwargs))
        except Exception as error:  # noqa: BLE001 -- every failure goes back to the caller
            error.add_note(f'in the synthesis process:\n{traceback.format_exc()}')
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


def _dumps(message) -> bytes:
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
def _formula_dispatch_table() -> dict:
    import copyreg
    import dataclasses
    from respec import ltl
    table = copyreg.dispatch_table.copy()
    for kind in (ltl.Const, ltl.Var, ltl.Not, ltl.And, ltl.Or, ltl.Implies, ltl.Iff, ltl.Next):
        table[kind] = _fields_reducer(kind, [field.name for field in dataclasses.fields(kind)])
    return table


def _fields_reducer(kind: type, names: list[str]):
    """A pickle reducer of ``kind``: rebuilt as ``kind(*fields)``."""
    if len(names) == 1:
        read = operator.attrgetter(names[0])
        return lambda node: (kind, (read(node),))
    read = operator.attrgetter(*names)
    return lambda node: (kind, read(node))


def _pickled(message) -> bytes:
    try:
        return _dumps(message)
    except Exception as error:  # noqa: BLE001 -- e.g. an exception that cannot be pickled
        return pickle.dumps(('error', SynthesisError(f'synthesis process: {error!r}')))


def _die_with_parent(parent_pid: int) -> None:
    """A child whose parent was killed (with no chance to stop it) ends too, within half a second.

    Not the kernel's parent-death signal (PR_SET_PDEATHSIG): it fires when the parent *thread*
    that started the child ends, and children are started from worker threads that come and go.
    """
    if os.getppid() != parent_pid:  # the parent died before the child got here
        os._exit(1)

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


if __name__ == '__main__':
    # Below the parent's priority: syntheses filling every core must not delay the parent's
    # answers (time limits, cancels, BUSY) on a loaded machine.
    os.nice(int(sys.argv[2]))
    from respec.nesting import run_with_deep_stack
    # Requests are served in a thread with room for any formula accepted (pickles of formula
    # trees are read and written recursively).
    run_with_deep_stack(_serve, int(sys.argv[1]), sys.argv[3])
