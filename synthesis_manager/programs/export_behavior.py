"""``behavior-synthesis export-behavior``: a synthesized behavior as a FlexBE behavior package.

    behavior-synthesis export-behavior --system atlas --initial-conditions stand_prep \\
        --goals look_down,pickup_object [--name NAME] [--package PKG] -o DIR

The task goes through the ``/behavior_synthesis`` action with the suite's nodes running
in-process (as ``execute`` does); the returned state machine is written to ``DIR/PKG``
(default package ``synthesized_flexbe_behaviors``) as FlexBE's editor saves a behavior: the
behavior module and its manifest, plus package.xml/setup.py for colcon
(``sm_generation.flexbe_behavior``). Any system can be exported: ATLAS-style systems through
their ``flexbe:`` section, CNU capability systems through their capabilities and the state
classes of the FlexBE workspace on ``AMENT_PREFIX_PATH``. ``--name`` names the behavior (default: from the goals,
e.g. "Look Down Pickup Object").

Exit status: 0 written; 2 bad name, package or configuration; 3 synthesis failed; 130, 143
stopped by SIGINT (Ctrl-C) or SIGTERM.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from respec.vocabulary.errors import ExitStatus, exit_status_help
from synthesis_manager.programs.send_goal import ProgressBar, add_goal_arguments, goal_from_args
from synthesis_manager.suite import SuiteUnavailableError, add_suite_arguments, in_process_suite

EXIT_STATUSES = (ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE, ExitStatus.TIMED_OUT, ExitStatus.UNAVAILABLE)


def add_arguments(parser):
    from sm_generation.flexbe_behavior import DEFAULT_PACKAGE

    parser.epilog = exit_status_help(*EXIT_STATUSES)
    add_goal_arguments(parser, with_options=False)
    add_suite_arguments(parser)
    parser.add_argument('--package', default=DEFAULT_PACKAGE, help=f'ROS package name (default {DEFAULT_PACKAGE})')
    parser.add_argument('--description', default='', help="the behavior's description")
    parser.add_argument('-o', '--output', required=True, metavar='DIR', help='write the package folder into DIR')


def run(args) -> int:
    from respec.vocabulary.errors import CodedError
    from respec.vocabulary.naming import parse_names
    from respec.robot import robot_system
    from sm_generation import SMGenerationError
    from sm_generation.config import generation_system_errors
    from sm_generation.for_system import behavior_flexbe_config
    from sm_generation.flexbe_behavior import (behavior_package, check_behavior_name, check_package_name,
                                               default_behavior_name)

    initial_conditions, goals = parse_names(args.initial_conditions), parse_names(args.goals)
    behavior_name = args.name or default_behavior_name(goals)
    try:  # bad names on the command line are usage errors, found before synthesis
        check_behavior_name(behavior_name)
        check_package_name(args.package)
    except CodedError as error:
        print(f'export-behavior: {error.code}: {error}', file=sys.stderr)
        return ExitStatus.USAGE
    try:  # a robot file refused: an error code of the pipeline, as from every command
        with generation_system_errors():
            system = robot_system(args.system, args.config_dir or None)
        config = behavior_flexbe_config(system)
    except CodedError as error:
        print(f'export-behavior: {error.code}: {error}', file=sys.stderr)
        return ExitStatus.FAILED
    progress = ProgressBar(stream=sys.stderr)  # the stream of now (the default is the one at import)
    outcome = None
    try:
        with in_process_suite(args, 'export_behavior_client') as (_, client):
            outcome = client.run(goal_from_args(args), feedback=progress)
    except SuiteUnavailableError as error:
        print(f'export-behavior: {error}', file=sys.stderr)
        return ExitStatus.UNAVAILABLE
    finally:
        progress.close(outcome)
    if not outcome.succeeded:
        print(f'export-behavior: synthesis failed: {outcome.error_name}: {outcome.message}', file=sys.stderr)
        return ExitStatus.for_error(outcome.error_name)
    description = (args.description or f'Synthesized for {args.system}: from {", ".join(initial_conditions)}, '
                   f'achieve {", ".join(goals)}.')
    try:
        package = behavior_package(outcome.machine, config, behavior_name, args.package, description=description,
                                   date=time.strftime('%a %b %d %Y'))
    except SMGenerationError as error:
        print(f'export-behavior: {error.code}: {error}', file=sys.stderr)
        return ExitStatus.FAILED
    folder = package.write(Path(args.output))
    print(f'wrote behavior "{behavior_name}" ({package.class_name}) as package {package.package}: {folder}')
    return ExitStatus.OK
