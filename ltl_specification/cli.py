"""``behavior-synthesis compile``: print the GR(1) specification of a task (ROS-free).

    behavior-synthesis compile --system atlas --initial-conditions stand_prep \\
        --goals look_down,pickup_object [--sm-outcomes finished,failed] [--unordered] \\
        [--format structuredslugs|slugsin|json] [-o FILE] [--config-dir DIR] \\
        [--custom-ltl FILE] [--explain] [--diagnose]

Bad input exits with status 2 and one line on stderr naming the error code and the item.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ltl_specification.compiler import compile_task, explain
from ltl_specification.errors import InvalidFormulaError
from ltl_specification.systems import task_system_errors
from respec.vocabulary.errors import CodedError, ExitStatus, exit_status_help
from respec.vocabulary.naming import parse_names
from respec.robot import robot_system
from respec.robot.files import add_config_dir_argument
from respec.untrusted import BoundedYamlError, load_bounded_yaml, read_bounded_file

FORMATS = ('structuredslugs', 'slugsin', 'json')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``compile`` options to ``parser``."""
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE)
    add_task_arguments(parser)
    parser.add_argument('--format', choices=FORMATS, default='structuredslugs', help='output format')
    parser.add_argument('-o', '--output', help='write to FILE instead of standard output')
    parser.add_argument('--explain', action='store_true', help='also print why each item is included (stderr)')
    parser.add_argument('--diagnose', action='store_true',
                        help='also check realizability; if the task cannot be done, say why on stderr '
                             '(pre-check, unrealizable core, environment play) and exit with status 1; '
                             'if it can, warn when the controller could win by forcing the environment '
                             'to break its assumptions (not well-separated)')


def add_task_arguments(parser: argparse.ArgumentParser) -> None:
    """The task's options, shared by every offline command that takes a task (compile, repair)."""
    parser.add_argument('--system', required=True, help='robot system, e.g. atlas (config/<system>.yaml)')
    parser.add_argument('--initial-conditions', default='',
                        help='comma-separated actions/control modes that hold initially '
                             '(default: the system\'s initial_mode)')
    parser.add_argument('--goals', required=True, help='comma-separated actions/control modes to achieve')
    parser.add_argument('--sm-outcomes', default='finished,failed',
                        help='finished,failed (stop on failure) or finished (retry failures)')
    parser.add_argument('--unordered', action='store_true', help='goals may be achieved in any order')
    add_config_dir_argument(parser)
    parser.add_argument('--custom-ltl', metavar='FILE',
                        help='YAML/JSON mapping of LTLSpecification sections to extra formulas')


def run(args: argparse.Namespace) -> int:
    """Compile and write the specification; returns the process exit status."""
    try:
        custom_ltl = read_custom_ltl(args.custom_ltl)
        with task_system_errors():
            system = robot_system(args.system, args.config_dir)
        spec = compile_task(system, args.initial_conditions, args.goals,
                            sm_outcomes=parse_names(args.sm_outcomes), strict_order=not args.unordered,
                            custom_ltl=custom_ltl)
    except CodedError as error:  # the task's and the robot files' own errors (a state class the workspace lacks)
        # One line naming the code and the item; a refusal's diagnosis (core, play) follows it.
        sentence, _, details = str(error).partition('\n')
        message = ' '.join(sentence.split())
        print(f'error: {error.code}: {message} [item: {error.item!r}]', file=sys.stderr)
        if getattr(error, 'diagnosis', None) is not None:
            print(details.rstrip('\n'), file=sys.stderr)
        return ExitStatus.FAILED
    if args.format == 'json':
        text = json.dumps(spec.to_text_sections(), indent=2) + '\n'
    elif args.format == 'slugsin':
        text = spec.to_slugsin()
    else:
        text = spec.to_structuredslugs()
    if args.output:
        Path(args.output).write_text(text)
    else:
        sys.stdout.write(text)
    if args.explain:
        print(explain(spec), file=sys.stderr)
    if args.diagnose:
        from ltl_specification.diagnosis import diagnose, explain_well_separation

        diagnosis = diagnose(spec)
        if diagnosis is not None:
            print(f'SPEC_UNSYNTHESIZABLE: {diagnosis.message()}', file=sys.stderr)
            return ExitStatus.FAILED
        warning = explain_well_separation(spec)   # realizable: but by cheating?
        if warning:
            print(warning, file=sys.stderr)
    return ExitStatus.OK


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='behavior-synthesis compile', description=__doc__.split('\n')[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(parser)
    return run(parser.parse_args(argv))


#: The largest --custom-ltl file read: what a goal may carry in all (synthesis_manager.limits).
MAX_CUSTOM_LTL_BYTES = 4 * 2**20
#: A custom LTL file is a mapping of sections to lists of formulas: deeper nesting is no such file.
MAX_CUSTOM_LTL_DEPTH = 8


def read_custom_ltl(path: str | None) -> Any:  # untrusted: compile_task checks it
    """The ``--custom-ltl`` file's mapping (None without one); InvalidFormulaError naming the file
    when it cannot be read, is not a regular file of at most MAX_CUSTOM_LTL_BYTES, is not UTF-8
    or not YAML/JSON within the bounds (``respec.untrusted``)."""
    if not path:
        return None
    try:
        return load_bounded_yaml(read_bounded_file(path, MAX_CUSTOM_LTL_BYTES), MAX_CUSTOM_LTL_DEPTH)
    except (OSError, BoundedYamlError) as error:
        raise InvalidFormulaError(f'cannot read custom LTL file {path}: {error}', item=path) from None
    except UnicodeDecodeError as error:
        raise InvalidFormulaError(f'cannot read custom LTL file {path}: not UTF-8 text '
                                  f'(byte {error.start})', item=path) from None
