"""``gr1synth``: a drop-in for the slugs command line (plus a structuredslugs converter).

    gr1synth [--explicitStrategy] [--jsonOutput] [--sysInitRoboticsSemantics]
             [--counterStrategy] [--explain] [--timeout S] [--memory-limit MB] INPUT [OUTPUT]
    gr1synth --convert INPUT.structuredslugs [OUTPUT.slugsin]

INPUT is ``.slugsin`` or ``.structuredslugs`` (chosen by extension). As slugs, it prints
``RESULT: Specification is realizable.`` or ``... unrealizable.`` on stderr and exits 0 in
both cases; only with ``--explicitStrategy`` (``--counterStrategy``) is a strategy
(counter-strategy) computed, and written to OUTPUT or stdout; only with ``--explain`` is the
reason for unrealizability computed and printed. A malformed or unreadable input exits with
status 1 (as slugs) and a ``file:line:col: ... near 'token'`` message; the time limit exits
with 3 (reading the input counts: a FIFO nobody writes to ends there too), the memory limit
with 4 (also while parsing). ``--timeout`` and ``--memory-limit`` must be finite numbers
>= 0 (0: no limit); anything else exits with 2, as every usage error. Formulas may be nested
up to respec.nesting.MAX_FORMULA_NESTING (10,000) levels deep; deeper ones are malformed (1).
Heavy modules (CUDD)
load only when a specification is synthesized, so ``--help`` is instant.
"""

from __future__ import annotations

import atexit
import os
import sys
import threading
from typing import Sequence

from ltl_synthesizer.command import parse_arguments, run
from respec.nesting import run_with_deep_stack


def main(argv: Sequence[str] | None = None) -> int:
    if argv is None:  # run as a program: Ctrl-C ends it at once, as it ends slugs, even while
        # one long CUDD operation holds the interpreter (a Python handler would wait for it).
        import signal
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    args = parse_arguments(argv)
    if args.serve:
        from ltl_synthesizer.serve import serve
        return serve(sys.stdin, sys.stdout)
    status = run_with_deep_stack(run, args)
    if argv is None:
        _exit_now(status)
    return status


def _exit_now(status: int) -> None:
    """End the program with ``status`` without Python's finalization, which frees every module
    and object one by one: 7-9 ms of CPU after a synthesis (its modules, dd's, CUDD's), a
    seventh of a small gridworld's whole run (issue 44). The outputs are flushed and the exit
    handlers run first (coverage's data, logging's), as at a normal exit; with another thread
    still running, or an output that cannot be flushed, the normal exit (which reports it)."""
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        return
    if threading.active_count() > 1:
        return
    atexit._run_exitfuncs()  # noqa: SLF001 - the handlers a normal exit runs
    os._exit(status)


if __name__ == '__main__':
    sys.exit(main())
