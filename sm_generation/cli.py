"""``behavior-synthesis generate-sm`` and ``python -m sm_generation``.

    behavior-synthesis generate-sm --system atlas --automaton task.yaml [--format yaml|json|dot|svg|png] [-o FILE]
    behavior-synthesis generate-sm --automaton strategy.json --spec task.structuredslugs -o task.svg

Exit status: 0 on success, 1 when generation fails (the error code and offending item
are printed), 2 on bad usage.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from respec.vocabulary.errors import ExitStatus, exit_status_help
from respec.vocabulary.naming import parse_names
from respec.robot import robot_system
from respec.robot.files import add_config_dir_argument
from sm_generation.automaton_io import load_automaton
from sm_generation.config import generation_system_errors
from sm_generation.errors import SMGenerationError
from sm_generation.export import RENDER_FORMATS, RenderError, render, to_dot, to_json, to_yaml
from sm_generation.for_system import generate_state_machine
from sm_generation.state_machine import validate_state_machine

FORMATS = ('yaml', 'json', 'dot', *RENDER_FORMATS)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE)
    parser.add_argument('--system', default='atlas', help='robot system (config/<system>.yaml); default atlas')
    parser.add_argument('--automaton', required=True, type=Path,
                        help='automaton file: our YAML/JSON format, or a slugs JSON strategy (needs --spec)')
    parser.add_argument('--spec', type=Path, help='the .structuredslugs spec a slugs strategy was made from')
    add_config_dir_argument(parser)
    parser.add_argument('--initial-conditions', default=None,
                        help='comma-separated initial conditions, e.g. stand_prep')
    parser.add_argument('--reduce', action='store_true', help='merge equivalent states')
    parser.add_argument('--format', choices=FORMATS, help='output format (default: from -o suffix, else yaml)')
    parser.add_argument('-o', '--output', type=Path, help='output file (default: standard output)')


def run(args: argparse.Namespace) -> int:
    fmt = args.format or _format_from_suffix(args.output) or 'yaml'
    if fmt in RENDER_FORMATS and args.output is None:
        print(f'error: --format {fmt} needs -o FILE', file=sys.stderr)
        return ExitStatus.USAGE
    initial_conditions = None
    if args.initial_conditions is not None:
        initial_conditions = parse_names(args.initial_conditions)
    try:
        automaton = load_automaton(args.automaton, args.spec)
        with generation_system_errors():
            system = robot_system(args.system, args.config_dir)
        machine = generate_state_machine(automaton, system, initial_conditions, args.reduce)
    except SMGenerationError as error:
        print(f'error: {error.code}: {error} (item: {error.item})', file=sys.stderr)
        return ExitStatus.FAILED
    problems = validate_state_machine(machine.to_instantiations())
    if problems:  # would be a bug in this package; report rather than write a broken file
        print('error: SM_GENERATION_FAILED: generated machine is inconsistent:\n  ' + '\n  '.join(problems),
              file=sys.stderr)
        return ExitStatus.FAILED
    if fmt in RENDER_FORMATS:
        try:
            render(to_dot(machine), args.output, fmt)
        except RenderError as error:
            print(f'error: {error} (item: {error.item})', file=sys.stderr)
            return ExitStatus.FAILED
        return ExitStatus.OK
    text = {'yaml': to_yaml, 'json': to_json, 'dot': to_dot}[fmt](machine)
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.write_text(text)
    return ExitStatus.OK


def _format_from_suffix(path: Path | None) -> str | None:
    if path is None:
        return None
    suffix = path.suffix.lstrip('.').lower()
    suffix = {'yml': 'yaml', 'gv': 'dot'}.get(suffix, suffix)
    return suffix if suffix in FORMATS else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='python -m sm_generation',
                                     description='Turn a synthesized automaton into a FlexBE state machine.')
    add_arguments(parser)
    return run(parser.parse_args(argv))
