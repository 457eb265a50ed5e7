"""The ``gr1synth`` command itself: its arguments, one run, and the writing of its outputs.

Shared by the command line (``ltl_synthesizer.cli``) and the resident mode
(``ltl_synthesizer.serve``), which answers each request line with one run; neither imports the
other. The command's behaviour is described in ``ltl_synthesizer.cli``.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import math
import os
import sys
import time
from typing import TYPE_CHECKING, Any, Callable, Iterable, Sequence

from respec.vocabulary.errors import ExitStatus, exit_status_help

if TYPE_CHECKING:  # loaded when a run needs them (a usage error answers without the synthesizer)
    from respec.spec import GR1Specification
    from ltl_synthesizer.interrupt import Limits
    from ltl_synthesizer.synthesizer import SynthesisResult

REALIZABLE_LINE = 'RESULT: Specification is realizable.'
UNREALIZABLE_LINE = 'RESULT: Specification is unrealizable.'


#: The command's switches (flags without a value): name, help.
SWITCHES = (
    ('--explicitStrategy', 'write an explicit-state strategy when realizable'),
    ('--jsonOutput', "strategies in slugs' JSON format"),
    ('--sysInitRoboticsSemantics', 'every state allowed by both init sections must be winning'),
    ('--counterStrategy', 'write a counter-strategy when unrealizable'),
    ('--convert', 'only convert INPUT.structuredslugs to slugsin'),
    ('--explain', 'when unrealizable, say why (losing initial states, blocked goal, a play)'),
    ('--check-well-separation', 'when realizable, check that the system cannot win by forcing the environment '
                                'to break its assumptions (Maoz & Ringert); print the result, or a warning '
                                'naming the assumptions involved'),
)
#: What a command line without --timeout or --memory-limit gets (argparse's defaults below).
DEFAULTS = {'timeout': None, 'memory_limit': 2048, 'serve': False}


@functools.cache
def _parser() -> argparse.ArgumentParser:
    """The command's argument parser, made once per process (0.6 ms: a tenth of a tiny
    specification's answer in the resident mode); parsing leaves it unchanged."""
    parser = argparse.ArgumentParser(
        prog='gr1synth', description='GR(1) synthesis with slugs-compatible input and output.',
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE, ExitStatus.TIMED_OUT,
                                ExitStatus.OUT_OF_MEMORY))
    for switch, meaning in SWITCHES:
        parser.add_argument(switch, action='store_true', help=meaning)
    parser.add_argument('--timeout', type=_limit, default=DEFAULTS['timeout'], metavar='SECONDS',
                        help='give up after this many seconds, reading the input included (exit status 3)')
    parser.add_argument('--memory-limit', type=_limit, default=DEFAULTS['memory_limit'], metavar='MB',
                        help='give up beyond this much memory (default 2048, 0: none; exit status 4)')
    parser.add_argument('--serve', action='store_true',
                        help='resident mode: read one request per line on stdin (a JSON list of '
                             'gr1synth arguments), answer one JSON line each on stdout')
    parser.add_argument('input', metavar='INPUT', nargs='?')
    parser.add_argument('output', metavar='OUTPUT', nargs='?')
    return parser


def _plain_arguments(argv: Sequence[str]) -> argparse.Namespace | None:
    """``argv`` parsed without argparse when it is only switches (SWITCHES or --serve, spelled
    out) followed by at most two file names (not starting with '-'), as argparse would parse
    it; None for anything else (argparse parses it: making the parser costs more than a tiny
    synthesis, 5 ms of CPU with the help texts, gettext's lookups and the terminal's size)."""
    switches = [switch for switch, _ in SWITCHES]
    given = 0
    while given < len(argv) and argv[given] in (*switches, '--serve'):
        given += 1
    files = argv[given:]
    if len(files) > 2 or any(name.startswith('-') for name in files):
        return None
    # in argparse's order (the parser's), so that even the Namespace's repr is the same
    values: dict[str, Any] = {switch[2:].replace('-', '_'): switch in argv[:given] for switch in switches}
    values.update(DEFAULTS, serve='--serve' in argv[:given], input=None, output=None)
    values.update(zip(('input', 'output'), files))
    return argparse.Namespace(**values)


def _limit(text: str) -> float:
    """A limit given on the command line: a finite number >= 0 (NaN would mean no limit)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f'must be a finite number >= 0, not {text[:40]!r}')
    return value


def parse_arguments(argv: Sequence[str] | None) -> argparse.Namespace:
    """The parsed gr1synth command line ``argv``; usage errors exit as argparse does (2), an
    OUTPUT without a strategy to write exits 1 (as slugs)."""
    args = _plain_arguments(sys.argv[1:] if argv is None else argv) or _parser().parse_args(argv)
    if args.serve:
        if args.input:
            _parser().error('--serve reads its requests from stdin: no INPUT')
    elif not args.input:
        _parser().error('the following arguments are required: INPUT')
    elif args.output and not (args.explicitStrategy or args.counterStrategy or args.convert):
        # As slugs ("too many file names"): an output file is only ever a strategy's.
        print('gr1synth: error: an OUTPUT file is written only with --explicitStrategy, '
              '--counterStrategy or --convert', file=sys.stderr)
        raise SystemExit(ExitStatus.FAILED)
    return args


#: Memory a parsed specification takes per byte of its text, at least (token-dense formulas
#: take about 22): an input over memory_limit / INPUT_EXPANSION bytes is refused unread.
INPUT_EXPANSION = 8


def read_specification(path: str, check: Callable[[], object] | None = None, deadline: float | None = None,
                       memory_limit: int | None = None) -> GR1Specification:
    """Parse a .slugsin or .structuredslugs file (by extension) into a GR1Specification;
    ``check`` (e.g. an ltl_synthesizer Interrupt) is called regularly while parsing. Reading
    that has not ended by ``deadline`` (a FIFO no one writes to) raises SynthesisCancelledError;
    an input over ``memory_limit`` / INPUT_EXPANSION bytes raises SynthesisMemoryError before
    it is read (a file, by its size) or as soon as that much is read (a pipe)."""
    from respec.parsing import parse_slugsin, parse_structuredslugs
    if path.endswith('.structuredslugs'):
        parse = parse_structuredslugs
    elif path.endswith('.slugsin'):
        parse = parse_slugsin
    else:
        raise ValueError(f"{path}: unknown input format (expected .slugsin or .structuredslugs)")
    max_chars = None if memory_limit is None else memory_limit // INPUT_EXPANSION
    return parse(_read_text(path, deadline, max_chars), filename=path, check=check)


def _read_text(path: str, deadline: float | None, max_chars: int | None = None) -> str:
    if deadline is None:
        return _read_at_most(path, max_chars)
    import threading
    from ltl_synthesizer.errors import SynthesisTimeoutError
    outcome: dict[str, Any] = {}   # 'text', or the 'error' reading raised

    def read() -> None:  # opening a FIFO blocks until a writer comes: in a thread the process may leave
        try:
            outcome['text'] = _read_at_most(path, max_chars)
        except BaseException as error:  # noqa: BLE001 - re-raised in the caller's thread
            outcome['error'] = error

    reader = threading.Thread(target=read, name='gr1synth-input', daemon=True)
    reader.start()
    reader.join(max(0.0, deadline - time.monotonic()))
    if reader.is_alive():
        raise SynthesisTimeoutError(f'timeout: {path} was still being read')
    if 'error' in outcome:
        raise outcome['error']
    return str(outcome['text'])


def _read_at_most(path: str, max_chars: int | None) -> str:
    """The text of ``path``, refused (SynthesisMemoryError) beyond ``max_chars``."""
    with open(path) as stream:
        if max_chars is None:
            return stream.read()
        size = os.fstat(stream.fileno()).st_size  # a file's size: refused before reading
        text = stream.read(max_chars + 1) if size <= max_chars else ''
    if size > max_chars or len(text) > max_chars:
        from ltl_synthesizer.errors import SynthesisMemoryError
        shown = f'{size:,} bytes' if size > max_chars else f'over {max_chars:,} characters'
        raise SynthesisMemoryError(
            f'the input has {shown}: reading it needs more than the memory limit of '
            f'{max_chars * INPUT_EXPANSION / 2**20:.0f} MB (an input may have 1/{INPUT_EXPANSION} '
            'of the limit)', item='memory_limit')
    return text


def synthesis_outcome(spec: GR1Specification, args: argparse.Namespace, limits: Limits,
                      stream: bool = False) -> SynthesisResult:
    """What a run of ``args`` prints and writes, as a SynthesisResult: the verdict, and the
    strategy, counter-strategy or explanation asked for. ``stream`` (in-process only): the
    strategy is extracted while it is written (bounded memory)."""
    from ltl_synthesizer.synthesizer import (SynthesisResult, counter_strategy, explain,
                                             explicit_strategy, solve, stream_strategy)
    solved = solve(spec, args.sysInitRoboticsSemantics, limits)
    result = SynthesisResult(solved.realizable)
    if solved.realizable and args.check_well_separation:
        from ltl_synthesizer.well_separation import check_well_separation
        result.stats['well_separation'] = check_well_separation(spec, limits, solved.game).summary()
    if solved.realizable and args.explicitStrategy:
        result.strategy = stream_strategy(solved) if stream else explicit_strategy(solved)
    elif not solved.realizable:
        if args.counterStrategy:
            result.counterstrategy = counter_strategy(solved)
        if args.explain:
            result.explanation = explain(solved)
    return result


def _write(text: str, output: str | None) -> None:
    _write_chunks([text], output)


def _write_chunks(chunks: Iterable[str], output: str | None) -> None:
    """Write text pieces as they come (a large strategy is never one string in memory).

    A file appears only complete: the pieces go to a hidden file beside it, renamed at the end,
    so an interrupted run (a streamed strategy is extracted while written) leaves no output.
    A device or FIFO (``/dev/stdout``) is written directly. A previous file is removed just
    before the rename: renamed over, ext4 (auto_da_alloc) writes the new file out at once
    (3.7 ms of a tiny specification's 10 ms in the resident mode; 0.07 ms removed first).
    """
    if output and os.path.exists(output) and not os.path.isfile(output):
        with open(output, 'w') as stream:
            stream.writelines(chunks)
    elif output:
        folder, name = os.path.split(os.path.abspath(output))
        partial = os.path.join(folder, f'.{name}.{os.getpid()}.partial')
        try:
            with open(partial, 'w') as stream:
                stream.writelines(chunks)
            with contextlib.suppress(FileNotFoundError):
                os.remove(output)
            os.replace(partial, output)
        finally:
            if os.path.exists(partial):
                os.remove(partial)
    else:
        sys.stdout.writelines(chunks)
        sys.stdout.flush()


def strategy_to_text(strategy: dict[str, Any]) -> str:
    """slugs' plain explicit-strategy format (``State n with rank r -> <a:0, b:1>``)."""
    lines = []
    for name in sorted(strategy['nodes'], key=int):
        node = strategy['nodes'][name]
        rank = node['rank']
        rank_text = f'({rank[0]},{rank[1]})' if isinstance(rank, list) else str(rank)
        values = ', '.join(f'{variable}:{value}' for variable, value in
                           zip(strategy['variables'], node['state']) if value is not None)
        lines.append(f'State {name} with rank {rank_text} -> <{values}>')
        if node['trans']:
            lines.append('\tWith successors : ' + ', '.join(str(t) for t in node['trans']))
        else:
            lines.append('\tWith no successors.')
        lines.append('')
    return '\n'.join(lines) + ('\n' if lines else '')


def run(args: argparse.Namespace) -> int:
    """One gr1synth run of parsed arguments (not --serve): its exit status, printing as slugs."""
    from respec.parsing import ParseError
    from ltl_synthesizer.errors import (SynthesisCancelledError, SynthesisError,
                                        SynthesisMemoryError)
    from ltl_synthesizer.interrupt import Limits

    deadline = time.monotonic() + args.timeout if args.timeout else None
    limits = Limits(deadline=deadline,
                    memory_limit=int(args.memory_limit * 2**20) if args.memory_limit > 0 else None)
    try:
        spec = read_specification(args.input, check=limits.interrupt(), deadline=deadline,
                                  memory_limit=limits.memory_limit)
    except SynthesisCancelledError as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return ExitStatus.TIMED_OUT
    except (SynthesisMemoryError, MemoryError) as error:
        print(f'gr1synth: error: memory limit: {error or "out of memory"} (while parsing {args.input})',
              file=sys.stderr)
        return ExitStatus.OUT_OF_MEMORY
    except (ParseError, OSError, ValueError) as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return ExitStatus.FAILED

    if args.convert:
        _write(spec.to_slugsin(), args.output)
        return ExitStatus.OK

    if deadline is not None:
        # With a time limit the synthesis runs in a child process, killed at the deadline even
        # in the middle of a long CUDD operation (checks between operations could be late).
        from ltl_synthesizer.isolated import SynthesisProcesses
        processes = SynthesisProcesses()
    try:
        if deadline is None:
            result = synthesis_outcome(spec, args, limits, stream=args.jsonOutput)
        else:
            result = processes.call(synthesis_outcome, (spec, args, limits), deadline=deadline)
    except SynthesisCancelledError as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return ExitStatus.TIMED_OUT
    except SynthesisMemoryError as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return ExitStatus.OUT_OF_MEMORY
    except SynthesisError as error:
        print(f'gr1synth: error: {args.input}: {error}', file=sys.stderr)
        return ExitStatus.FAILED
    finally:
        if deadline is not None:
            processes.close()
    print(REALIZABLE_LINE if result.realizable else UNREALIZABLE_LINE, file=sys.stderr)
    if 'well_separation' in result.stats:
        print(result.stats['well_separation'], file=sys.stderr)
    if not result.realizable and args.explain and result.explanation:
        print(result.explanation, file=sys.stderr)
    if result.realizable and args.explicitStrategy:
        strategy = result.strategy
    elif not result.realizable and args.counterStrategy:
        strategy = result.counterstrategy
    else:
        return ExitStatus.OK
    assert strategy is not None  # asked for, so made (synthesis_outcome)
    try:
        if args.jsonOutput:
            from ltl_synthesizer.strategy import strategy_json_chunks
            _write_chunks(strategy_json_chunks(strategy), args.output)
        else:
            _write(strategy_to_text(strategy), args.output)
    except SynthesisMemoryError as error:  # a streamed strategy is extracted while written
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return ExitStatus.OUT_OF_MEMORY
    return ExitStatus.OK
