"""``gr1synth --serve``: a resident synthesizer for tools that call it thousands of times.

Each request is one line on stdin: a JSON list of gr1synth arguments (the command line without
``gr1synth``), e.g. ``["--explicitStrategy", "--jsonOutput", "spec.slugsin"]``. Each answer is
one line on stdout: ``{"status": exit status, "stdout": ..., "stderr": ...}``, exactly what the
command would have printed and returned. The interpreter and CUDD load once, so a tiny
specification costs only its synthesis. Ends at end of input.
"""

from __future__ import annotations

import contextlib
import io
import json
from typing import Any, Iterable, TextIO

from respec.vocabulary.errors import ExitStatus

from ltl_synthesizer.command import parse_arguments, run
from respec.nesting import run_with_deep_stack


def serve(requests: Iterable[str], answers: TextIO) -> int:
    for line in requests:
        if not line.strip():
            continue
        answers.write(json.dumps(answer(line)) + '\n')
        answers.flush()
    return 0


def answer(line: str) -> dict[str, Any]:
    """The outcome of one request line (a malformed request is an answer, not a crash)."""
    stdout, stderr = io.StringIO(), io.StringIO()
    try:
        argv = json.loads(line)
        if not isinstance(argv, list) or not all(isinstance(item, str) for item in argv):
            raise ValueError('a request is a JSON list of strings')
    except ValueError as error:
        return {'status': ExitStatus.FAILED, 'stdout': '', 'stderr': f'gr1synth: error: {error}\n'}
    status: int
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        try:
            args = parse_arguments(argv)
            if args.serve:
                print('gr1synth: error: --serve inside a request', file=stderr)
                status = ExitStatus.FAILED
            else:
                status = run_with_deep_stack(run, args)
        except SystemExit as exit_:  # argparse's usage errors
            status = exit_.code if isinstance(exit_.code, int) else ExitStatus.FAILED
    return {'status': status, 'stdout': stdout.getvalue(), 'stderr': stderr.getvalue()}
