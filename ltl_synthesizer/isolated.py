"""Syntheses in child processes that a cancel, a deadline or a shutdown ends at once.

The synthesizer checks its limits between BDD operations, but one CUDD operation on a large
specification can run for seconds, holding Python's GIL: in the same process, nothing else
runs meanwhile (not a cancel request, not a signal handler). Here each synthesis runs in a
long-lived child process; the caller waits in short polls and kills the child when the
synthesis must stop, so stopping takes milliseconds whatever CUDD is doing, and the CPU and
memory are released with the process. Idle children are kept for the next synthesis (a new
one costs the start of a Python interpreter, a fraction of a second).

    processes = SynthesisProcesses()
    result = processes.synthesize(spec, cancel=event, deadline=time.monotonic() + 60)
    explanation = processes.call('ltl_specification.diagnosis:explain_unsynthesizable', args,
                                 cancel=event, deadline=deadline)  # other solver work, the same way
    processes.close()

``synthesize`` has the arguments, results and exceptions of :func:`ltl_synthesizer.synthesize`;
``call`` runs any importable function. A child that dies (killed from outside, crashed) raises
:class:`SynthesisProcessDied`; a cancel or the deadline raises SynthesisCancelled.
"""

from __future__ import annotations

import importlib
import os
import pickle
import select
import subprocess
import sys
import threading
import time
import traceback

from ltl_synthesizer.errors import SynthesisCancelled, SynthesisError

# How often the caller looks at its cancel flag and deadline while a child works.
POLL_SECONDS = 0.02
_LENGTH_BYTES = 8


class SynthesisProcessDied(SynthesisError):
    """The process running the synthesis ended without an answer."""


SYNTHESIZE = 'ltl_synthesizer.synthesizer:synthesize'


class _Child:
    """One child process (``python -m ltl_synthesizer.isolated``), spoken to through its stdin
    and stdout: length-prefixed pickles, a request ('module:function', args, kwargs) in, an
    answer ('result', value) or ('error', exception) out."""

    def __init__(self):
        self.process = subprocess.Popen([sys.executable, '-m', 'ltl_synthesizer.isolated', str(os.getpid())],
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE)

    def send(self, message) -> None:
        data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
        self.process.stdin.write(len(data).to_bytes(_LENGTH_BYTES, 'little') + data)
        self.process.stdin.flush()

    def answered(self, timeout: float) -> bool:
        return bool(select.select([self.process.stdout], [], [], timeout)[0])

    def receive(self):
        return pickle.loads(_read_exactly(self.process.stdout, int.from_bytes(
            _read_exactly(self.process.stdout, _LENGTH_BYTES), 'little')))

    def alive(self) -> bool:
        return self.process.poll() is None

    def kill(self) -> None:
        if self.alive():
            self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stdout):
            try:
                stream.close()
            except OSError:  # a request half-written to a killed child
                pass


def _read_exactly(stream, size: int) -> bytes:
    data = stream.read(size)
    if len(data) != size:
        raise EOFError('the synthesis process closed its output')
    return data


class SynthesisProcesses:
    """A pool of synthesis child processes, one per synthesis running at the same time."""

    def __init__(self):
        self._lock = threading.Lock()
        self._idle: list[_Child] = []
        self._busy: set[_Child] = set()
        self._closed = False

    def prepare(self, count: int = 1) -> None:
        """Start ``count`` idle children now, so that the first syntheses need not wait."""
        with self._lock:
            while len(self._idle) < count and not self._closed:
                self._idle.append(_Child())

    def synthesize(self, spec, cancel: threading.Event | None = None, deadline: float | None = None,
                   **arguments):
        """``ltl_synthesizer.synthesize(spec, cancel=..., deadline=..., **arguments)`` in a child."""
        return self.call(SYNTHESIZE, (spec,), dict(arguments, deadline=deadline), cancel=cancel, deadline=deadline)

    def call(self, target: str, args=(), kwargs=None, cancel: threading.Event | None = None,
             deadline: float | None = None):
        """``function(*args, **kwargs)`` in a child, where ``target`` is 'module:function'.
        The child is killed once ``cancel`` is set or at ``deadline`` (time.monotonic())."""
        child = self._take()
        answer = None
        try:
            child.send((target, tuple(args), dict(kwargs or {})))
            while not child.answered(POLL_SECONDS):
                if cancel is not None and cancel.is_set():
                    raise SynthesisCancelled('cancelled')
                if deadline is not None and time.monotonic() >= deadline:
                    raise SynthesisCancelled('timeout')
                if not child.alive():
                    raise self._ended(child)
            answer = child.receive()
        except (EOFError, OSError, ValueError):  # the child died, or close() closed the pipes
            raise self._ended(child) from None
        finally:
            self._give_back(child, reusable=answer is not None)
        kind, value = answer
        if kind == 'error':
            raise value
        return value

    def _ended(self, child: _Child) -> SynthesisError:
        if self._closed:
            return SynthesisCancelled('cancelled')
        return SynthesisProcessDied(f'the synthesis process ended (exit code {child.process.poll()}) '
                                    'without an answer', item='synthesis process')

    def close(self) -> None:
        """Kill every child, busy or idle (at shutdown)."""
        with self._lock:
            self._closed = True
            children = self._idle + list(self._busy)
            self._idle, self._busy = [], set()
        for child in children:
            child.kill()

    def _take(self) -> _Child:
        with self._lock:
            if self._closed:
                raise SynthesisCancelled('cancelled')
            child = self._idle.pop() if self._idle else None
        if child is None or not child.alive():
            if child is not None:
                child.kill()
            child = _Child()
        with self._lock:
            self._busy.add(child)
        return child

    def _give_back(self, child: _Child, reusable: bool) -> None:
        with self._lock:
            self._busy.discard(child)
            keep = reusable and not self._closed
            if keep:
                self._idle.append(child)
            elif not self._closed and not self._idle:
                # A replacement starts now, while the caller reports the stop.
                self._idle.append(_Child())
        if not keep:
            child.kill()


def _serve(parent_pid: int) -> None:
    """The child: answer requests until stdin closes or the parent is gone."""
    _die_with_parent(parent_pid)
    requests = sys.stdin.buffer
    answers = os.fdopen(os.dup(sys.stdout.fileno()), 'wb')
    sys.stdout = sys.stderr  # stray prints must not corrupt the answers
    _function(SYNTHESIZE)  # imported now: the first synthesis need not wait for it
    while True:
        try:
            target, args, kwargs = pickle.loads(_read_exactly(requests, int.from_bytes(
                _read_exactly(requests, _LENGTH_BYTES), 'little')))
        except EOFError:
            return
        try:
            answer = ('result', _function(target)(*args, **kwargs))
        except Exception as error:  # noqa: BLE001 -- every failure goes back to the caller
            error.add_note(f'in the synthesis process:\n{traceback.format_exc()}')
            answer = ('error', error)
        try:
            data = pickle.dumps(answer, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as error:  # noqa: BLE001 -- e.g. an exception that cannot be pickled
            data = pickle.dumps(('error', SynthesisError(f'synthesis process: {error!r}')))
        answers.write(len(data).to_bytes(_LENGTH_BYTES, 'little') + data)
        answers.flush()


def _function(target: str):
    module, _, name = target.partition(':')
    return getattr(importlib.import_module(module), name)


def _die_with_parent(parent_pid: int) -> None:
    """A child whose parent was killed (with no chance to stop it) ends too: at once on Linux
    (the kernel's parent-death signal), else within half a second."""
    try:
        import ctypes
        import signal
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent_pid:  # the parent died before the signal was asked for
        os._exit(1)

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


if __name__ == '__main__':
    _serve(int(sys.argv[1]))
