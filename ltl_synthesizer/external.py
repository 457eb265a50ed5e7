"""Running a slugs-compatible synthesizer executable, the way the original stack ran slugs.

    <executable> --explicitStrategy --jsonOutput [--sysInitRoboticsSemantics] in.slugsin out.json

Realizability is read from the ``RESULT: Specification is (un)realizable.`` line that slugs
prints on stderr; the strategy is the JSON file it writes when realizable. The process is
killed on timeout or cancellation.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

from ltl_synthesizer.errors import SynthesisCancelledError, SynthesisError, SynthesisTimeoutError
from respec.vocabulary.errors import ErrorCode

REALIZABLE_LINE = 'RESULT: Specification is realizable.'
UNREALIZABLE_LINE = 'RESULT: Specification is unrealizable.'
_POLL_SECONDS = 0.05


class ExternalSynthesizerError(SynthesisError):
    """The executable is missing, crashed, wrote no usable result; ``item`` names the executable."""

    code = ErrorCode.SYNTHESIZER_BACKEND_FAILED


def run_external_synthesizer(executable: str, slugsin_path: str | Path, output_path: str | Path,
                             robotics_semantics: bool = True, timeout: float | None = None,
                             cancel: threading.Event | None = None) -> tuple[bool, dict[str, Any] | None, str]:
    """Run ``executable`` on ``slugsin_path``; return (realizable, strategy or None, stderr).

    Raises ExternalSynthesizerError (code SYNTHESIZER_BACKEND_FAILED) when the executable
    cannot be started, exits abnormally, prints neither RESULT line, or claims realizability
    without a readable strategy; SynthesisCancelledError with reason 'timeout' (code
    SYNTHESIS_TIMEOUT) after ``timeout`` seconds or 'cancelled' (code PREEMPTED) when
    ``cancel`` is set. The process (and its process group) is killed in both cases.
    """
    command = [executable, '--explicitStrategy', '--jsonOutput']
    if robotics_semantics:
        command.append('--sysInitRoboticsSemantics')
    command += [str(slugsin_path), str(output_path)]
    output_path = Path(output_path)
    if output_path.exists():
        output_path.unlink()  # a stale strategy must never pass for a fresh one

    try:
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   text=True, start_new_session=True)
    except OSError as error:
        raise ExternalSynthesizerError(
            f'cannot run synthesizer {executable!r}: {error.strerror or error}', item=executable) from error

    stdout, stderr = _wait(process, executable, timeout, cancel)
    if REALIZABLE_LINE in stderr:
        realizable = True
    elif UNREALIZABLE_LINE in stderr:
        realizable = False
    else:
        raise ExternalSynthesizerError(
            f'synthesizer {executable!r} exited with status {process.returncode} without a RESULT line'
            + _tail(stderr or stdout), item=executable)
    if process.returncode != 0:
        raise ExternalSynthesizerError(
            f'synthesizer {executable!r} exited with status {process.returncode}' + _tail(stderr),
            item=executable)
    if not realizable:
        return False, None, stderr
    try:
        strategy = json.loads(output_path.read_text())
    except (OSError, ValueError) as error:
        raise ExternalSynthesizerError(
            f'synthesizer {executable!r} reported a realizable specification but its strategy '
            f'{str(output_path)!r} is unreadable: {error}', item=executable) from error
    return True, strategy, stderr


def _wait(process: subprocess.Popen[str], executable: str, timeout: float | None,
          cancel: threading.Event | None) -> tuple[str, str]:
    """Collect the output; kill the process group on timeout or cancellation."""
    deadline = None if timeout is None else time.monotonic() + timeout
    while True:
        wait = _POLL_SECONDS
        if deadline is not None:
            wait = min(wait, max(deadline - time.monotonic(), 0))
        try:
            interruptible = cancel is not None or deadline is not None
            return process.communicate(timeout=wait if interruptible else None)
        except subprocess.TimeoutExpired:
            pass
        if cancel is not None and cancel.is_set():
            _kill(process)
            raise SynthesisCancelledError('cancelled')
        if deadline is not None and time.monotonic() >= deadline:
            _kill(process)
            raise SynthesisTimeoutError()


def _kill(process: subprocess.Popen[str]) -> None:
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        process.kill()
    process.communicate()


def _tail(text: str, lines: int = 5) -> str:
    last = [line for line in text.strip().splitlines()][-lines:]
    return (': ' + ' | '.join(last)) if last else ''
