"""``behavior-synthesis demo`` (``make run``): the paper's task end to end, in one process.

Starts the four nodes in-process on a private ROS domain, sends I={stand_prep},
G=[look_down, pickup_object], prints the specification size, realizability, automaton size
and the state machine as a tree, and writes every artifact to an output folder.
"""

from __future__ import annotations

import sys
from pathlib import Path

from respec.vocabulary.errors import ExitStatus, exit_status_help
from sm_generation.export import render, to_dot, to_json, to_yaml
from synthesis_manager.web.picture import render_svg
from synthesis_manager.programs.send_goal import ProgressBar, add_goal_arguments, goal_from_args, print_summary
from synthesis_manager.suite import SuiteUnavailableError, add_suite_arguments, in_process_suite


def add_arguments(parser):
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE, ExitStatus.TIMED_OUT,
                                     ExitStatus.UNAVAILABLE)
    add_goal_arguments(parser, with_options=False)
    parser.set_defaults(name='demo')
    add_suite_arguments(parser)
    parser.add_argument('--output-dir', default='out/demo', help='where to write the artifacts')


def write_artifacts(outcome, directory: Path) -> list[Path]:
    """StateInstantiation YAML/JSON and pictures of the state machine (byproducts are already there)."""
    machine = outcome.machine
    written = []
    for name, text in (('state_machine.yaml', to_yaml(machine)), ('state_machine.json', to_json(machine)),
                       ('state_machine.dot', to_dot(machine))):
        path = directory / name
        path.write_text(text)
        written.append(path)
    # The SVG as the GUI draws it (dot, else Graphviz compiled to WebAssembly: no system package
    # needed); the PNG needs dot. Either may be missing: say so and carry on.
    for suffix, write in (('svg', lambda path: path.write_bytes(render_svg(to_dot(machine)))),
                          ('png', lambda path: render(to_dot(machine), path))):
        path = directory / f'state_machine.{suffix}'
        try:
            write(path)
            written.append(path)
        except Exception as error:  # noqa: BLE001 - a picture is a byproduct: without one the demo goes on
            print(f'(no {suffix} picture: {error})', file=sys.stderr)
    return written


def run(args) -> int:
    directory = Path(args.output_dir).resolve()
    directory.mkdir(parents=True, exist_ok=True)
    args.byproducts_dir = str(directory)
    print(f'Task: from {args.initial_conditions}: {args.goals} (system {args.system})')
    try:
        with in_process_suite(args, 'demo_client') as (_, client):
            progress = ProgressBar()
            outcome = client.run(goal_from_args(args), feedback=progress)
            progress.close(outcome)
    except SuiteUnavailableError as error:
        print(f'demo: {error}', file=sys.stderr)
        return ExitStatus.UNAVAILABLE
    print_summary(outcome)
    if not outcome.succeeded:
        return ExitStatus.for_error(outcome.error_name)
    print('realizable: yes')
    written = write_artifacts(outcome, directory)
    byproducts = sorted(directory.glob(f'{args.name}.*'))
    print(f'artifacts in {directory}:')
    for path in byproducts + written:
        print(f'  {path.name}')
    return ExitStatus.OK
