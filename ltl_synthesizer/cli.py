"""``gr1synth``: a drop-in for the slugs command line (plus a structuredslugs converter).

    gr1synth [--explicitStrategy] [--jsonOutput] [--sysInitRoboticsSemantics]
             [--counterStrategy] INPUT [OUTPUT]
    gr1synth --convert INPUT.structuredslugs [OUTPUT.slugsin]

INPUT is ``.slugsin`` or ``.structuredslugs`` (chosen by extension). As slugs, it prints
``RESULT: Specification is realizable.`` or ``... unrealizable.`` on stderr and exits 0 in
both cases; the strategy (or counter-strategy) goes to OUTPUT or stdout. A malformed file
exits with status 2 and a ``file:line:col: ... near 'token'`` message.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REALIZABLE_LINE = 'RESULT: Specification is realizable.'
UNREALIZABLE_LINE = 'RESULT: Specification is unrealizable.'
EXIT_USAGE = 2


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='gr1synth', description='GR(1) synthesis with slugs-compatible input and output.')
    parser.add_argument('--explicitStrategy', action='store_true',
                        help='write an explicit-state strategy when realizable')
    parser.add_argument('--jsonOutput', action='store_true', help="strategies in slugs' JSON format")
    parser.add_argument('--sysInitRoboticsSemantics', action='store_true',
                        help='every state allowed by both init sections must be winning')
    parser.add_argument('--counterStrategy', action='store_true',
                        help='write a counter-strategy when unrealizable')
    parser.add_argument('--convert', action='store_true',
                        help='only convert INPUT.structuredslugs to slugsin')
    parser.add_argument('--timeout', type=float, default=None, metavar='SECONDS',
                        help='give up after this many seconds (exit status 3)')
    parser.add_argument('--quiet', action='store_true', help='no explanation after RESULT')
    parser.add_argument('input', metavar='INPUT')
    parser.add_argument('output', metavar='OUTPUT', nargs='?')
    return parser


def read_specification(path: str):
    """Parse a .slugsin or .structuredslugs file (by extension) into a GR1Specification."""
    from respec.parsing import parse_slugsin, parse_structuredslugs
    text = Path(path).read_text()
    if path.endswith('.structuredslugs'):
        return parse_structuredslugs(text, filename=path)
    if path.endswith('.slugsin'):
        return parse_slugsin(text, filename=path)
    raise ValueError(f"{path}: unknown input format (expected .slugsin or .structuredslugs)")


def _write(text: str, output: str | None) -> None:
    if output:
        Path(output).write_text(text)
    else:
        sys.stdout.write(text)
        sys.stdout.flush()


def strategy_to_text(strategy: dict) -> str:
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


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from respec.parsing import ParseError
    from ltl_synthesizer import SynthesisCancelled, SynthesisError, synthesize
    from ltl_synthesizer.strategy import strategy_to_json

    try:
        spec = read_specification(args.input)
    except ParseError as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return EXIT_USAGE
    except (OSError, ValueError) as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return EXIT_USAGE

    if args.convert:
        _write(spec.to_slugsin(), args.output)
        return 0

    deadline = time.monotonic() + args.timeout if args.timeout else None
    try:
        result = synthesize(spec, robotics_semantics=args.sysInitRoboticsSemantics,
                            deadline=deadline, counterstrategy=args.counterStrategy,
                            explain=not args.quiet)
    except SynthesisCancelled as error:
        print(f'gr1synth: error: {error}', file=sys.stderr)
        return 3
    except SynthesisError as error:
        print(f'gr1synth: error: {args.input}: {error}', file=sys.stderr)
        return EXIT_USAGE

    print(REALIZABLE_LINE if result.realizable else UNREALIZABLE_LINE, file=sys.stderr)
    if not result.realizable and result.explanation and not args.quiet:
        print(result.explanation, file=sys.stderr)
    printer = strategy_to_json if args.jsonOutput else strategy_to_text
    if result.realizable and args.explicitStrategy:
        _write(printer(result.strategy), args.output)
    elif not result.realizable and args.counterStrategy:
        _write(printer(result.counterstrategy), args.output)
    return 0


if __name__ == '__main__':
    sys.exit(main())
