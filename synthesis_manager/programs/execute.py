"""``behavior-synthesis execute``: synthesize a behavior, run it on the simulated robot, check the run.

The simulated robot is ATLAS's MuJoCo humanoid for a robot of our own format, and a simulated
capability robot (each state answers an outcome, no physics: ``execute_capability_robot``) for
a robot in CNU's capability format.

The task goes through the ``/behavior_synthesis`` action with the suite's nodes running
in-process (as ``demo`` does); the returned state machine runs on the MuJoCo simulator
(in-process, or with ``--ros-sim`` through the ``atlas_sim`` node over ROS) and the
executed trace is checked against the returned specification.

    behavior-synthesis execute --initial-conditions stand_prep --goals look_down,pickup_object
    behavior-synthesis execute --goals pickup_object --fail pickup_object --expect failed
    behavior-synthesis execute --goals pickup_object --sm-outcomes finished --fail-first pickup_object:2
    behavior-synthesis execute --json --record out/run      # PNG frames (motion, key moments) + timeline.png

Mission mode: ``--then GOALS`` (repeatable) adds goal batches, run one after another on the
same simulated robot; each is synthesized from where the previous one left the robot (also
after a failure), i.e. with the initial condition ``current``: with ``--ros-sim`` the server
reads them from the ``atlas_sim/state`` topic, otherwise they are read from the simulator.
``--initial-conditions current`` does the same for the first batch. The paper's second demo,
on the fly::

    behavior-synthesis execute --ros-sim --goals look_down,pickup_object --then footstep_execution

With ``--json`` a mission prints ``{"batches": [...], "exit_code"}``, one entry per batch
with its goals, initial conditions, synthesis time, outcome and trace check.

    behavior-synthesis execute --engine flexbe --goals look_down,pickup_object   # on flexbe_core

With ``--engine flexbe`` the machine is exported as a FlexBE behavior and run by the real
FlexBE engine (``synthesis_manager.ros.flexbe_engine``), its states driving the simulator
node over ROS; the report is the same.

Exit status: see the table below (from respec.vocabulary.errors.ExitStatus). A mission stops at the
first batch that ends with anything but 0 or 6 (another SM outcome) and exits with it; otherwise it
exits with the status of its last batch (earlier batches may end in any SM outcome).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

from atlas_sim.closed_loop import DeferredEvents, run_and_check
from atlas_sim.executive.errors import ExecutionError
from respec.vocabulary.errors import ExitStatus, exit_status_help
from respec.nesting import run_with_deep_stack
from respec.parsing import spec_from_text_sections
from synthesis_manager.programs.send_goal import ProgressBar, add_goal_arguments, goal_from_args, print_summary
from synthesis_manager.suite import SuiteUnavailableError, add_suite_arguments, in_process_suite

EXIT_STATUS_HELP = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE, ExitStatus.TIMED_OUT,
                                    ExitStatus.UNAVAILABLE, ExitStatus.OTHER_OUTCOME, ExitStatus.VIOLATIONS,
                                    ExitStatus.NOT_FINISHED)


def add_arguments(parser):
    parser.epilog = EXIT_STATUS_HELP
    add_goal_arguments(parser, with_options=False)
    parser.set_defaults(name='execute')
    add_suite_arguments(parser)
    group = parser.add_argument_group('execution')
    group.add_argument('--fail', action='append', default=[], metavar='ACTION[,ACTION]',
                       help='capabilities that always fail (repeatable); a capability robot: CAPABILITY[:OUTCOME], '
                            'the outcome its state always returns (default: the one it fails with)')
    group.add_argument('--sensor', action='append', default=[], metavar='NAME[=true|false]',
                       help="a capability robot's sensor (a spec INPUT) as its environment reads it (repeatable)")
    group.add_argument('--fail-first', action='append', default=[], metavar='ACTION:K',
                       help='the first K attempts of ACTION fail (repeatable, comma-separated)')
    group.add_argument('--seed', type=int, default=None, help='seed of probabilistic faults')
    group.add_argument('--then', action='append', default=[], metavar='GOAL[,GOAL]',
                       help='another goal batch, synthesized from where the previous batch left the '
                            'robot (repeatable: a mission)')
    group.add_argument('--expect', default='finished', metavar='OUTCOME',
                       help='the SM outcome the run (a mission: its last batch) should end in '
                            '(default: finished)')
    group.add_argument('--engine', choices=('ours', 'flexbe'), default='ours',
                       help='who runs the state machine: our fast executive (default) or the real FlexBE '
                            'engine (flexbe_core, e.g. from `make flexbe`; implies --ros-sim)')
    group.add_argument('--verbose', action='store_true',
                       help="with --engine flexbe: show flexbe_core's INFO log lines and progress notes")
    group.add_argument('--ros-sim', action='store_true',
                       help='run the simulator as the atlas_sim node and drive it over ROS')
    group.add_argument('--speed', type=float, default=10.0,
                       help='with --ros-sim: sim seconds per wall second (0: as fast as possible)')
    group.add_argument('--max-robot-time', type=float, default=300.0, help='robot seconds before giving up')
    group.add_argument('--json', action='store_true',
                       help='print {"outcome", "trace", "trace_check", "fallen", ...} as one JSON object')
    group.add_argument('--record', metavar='DIR',
                       help='save PNG frames of the motion (16 per robot second) and of key moments, and '
                            'timeline.png, in DIR')


def run(args) -> int:
    from respec.robot import for_description, robot_system
    from respec.robot.abstraction import RobotAbstraction
    from respec.robot.cnu import CapabilitySystem
    from respec.robot.files import SystemConfigError

    if args.engine == 'flexbe':
        if args.record:
            print('execute: --record is not available with --engine flexbe', file=sys.stderr)
            return ExitStatus.USAGE
        missing = _missing_flexbe_engine()
        if missing:  # the command line is fine: a program it needs is not installed
            print(f'execute: {missing}', file=sys.stderr)
            return ExitStatus.UNAVAILABLE
    if args.record:
        os.environ.setdefault('MUJOCO_GL', 'egl')  # before anything imports mujoco
    try:
        system = robot_system(args.system, args.config_dir or None)
    except SystemConfigError as error:
        print(f'execute: {error.code}: {error}', file=sys.stderr)
        return ExitStatus.FAILED
    runners = {RobotAbstraction: execute_mode_robot, CapabilitySystem: execute_capability_robot}
    return for_description(runners, system, missing=execute_mode_robot)(args, system)


def execute_mode_robot(args, system) -> int:
    """``execute`` for a robot of our own format: its machine on atlas_sim's simulated robot."""
    from atlas_sim.simulator.factory import FaultSpecError, InitialConditionError, make_simulator, parse_faults
    from ltl_specification.errors import InvalidInitialConditionsError
    from ltl_specification.initial_conditions import asks_for_robot_state
    from respec.vocabulary.naming import parse_names
    from respec.robot.files import SystemConfigError

    initial_conditions = parse_names(args.initial_conditions)
    batches = [parse_names(args.goals), *(parse_names(goals) for goals in args.then)]
    try:  # the simulator first: a bad fault or start is a usage error, found before synthesis
        if args.sensor:
            raise FaultSpecError(f'--sensor is for capability robots; {system.name} reads its sensors in the simulator')
        faults = parse_faults(parse_names(args.fail), parse_names(args.fail_first))
        start = [] if asks_for_robot_state(initial_conditions) else initial_conditions
        simulator = make_simulator(system, start, faults, args.seed)
    except (FaultSpecError, InitialConditionError, InvalidInitialConditionsError, SystemConfigError) as error:
        print(f'execute: {error}', file=sys.stderr)
        return ExitStatus.USAGE
    log = sys.stderr if args.json else sys.stdout
    report = {'system': args.system, 'faults': faults}
    code = _synthesize_and_execute(args, system, simulator, initial_conditions, batches, report, log)
    report['exit_code'] = code
    if args.json:
        print(json.dumps(report))
    return code


def execute_capability_robot(args, system) -> int:
    """``execute`` for a robot of CNU's capability format: its machine on the simulated capability
    robot (``atlas_sim.executive.capability_run``), checked against its specification."""
    from argparse import Namespace

    from atlas_sim.executive.capability_run import CapabilityRun, ScriptError, parse_script
    from respec.vocabulary.errors import CodedError
    from respec.vocabulary.naming import parse_names
    from respec.robot.state_library import capability_outcomes, workspace_state_library

    unsupported = [flag for flag, given in (('--engine flexbe', args.engine == 'flexbe'), ('--ros-sim', args.ros_sim),
                                            ('--record', args.record), ('--then', args.then),
                                            ('--fail-first', args.fail_first)) if given]
    if unsupported:
        print(f'execute: {", ".join(unsupported)}: not available for a capability robot ({system.name}); its '
              'machine runs on the simulated capability robot (start it onboard with start-behavior)', file=sys.stderr)
        return ExitStatus.USAGE
    try:
        outcomes = capability_outcomes(system.capabilities, workspace_state_library())
        script = parse_script(system.capabilities, outcomes, parse_names(args.fail), args.sensor)
    except ScriptError as error:
        print(f'execute: {error}', file=sys.stderr)
        return ExitStatus.USAGE
    except CodedError as error:
        print(f'execute: {error.code}: {error}', file=sys.stderr)
        return ExitStatus.FAILED
    log = sys.stderr if args.json else sys.stdout
    report = {'system': system.name, 'goals': parse_names(args.goals), 'script': {
        'fail': script.outcomes, 'sensors': script.sensors}}
    try:
        with in_process_suite(args, 'execute_client') as (_, client):
            progress = None if args.json else ProgressBar()
            outcome = client.run(goal_from_args(Namespace(**vars(args))), feedback=progress)
            if progress:
                progress.close(outcome)
    except SuiteUnavailableError as error:
        print(f'execute: {error}', file=sys.stderr)
        return ExitStatus.UNAVAILABLE
    report['synthesis'] = {'error_name': outcome.error_name, 'message': outcome.message,
                           'seconds': round(outcome.seconds, 4), 'states': len(outcome.states)}
    if not args.json:
        print_summary(outcome, stream=log)
    if not outcome.succeeded:
        print(f'execute: synthesis failed: {outcome.error_name}: {outcome.message}', file=sys.stderr)
        report['exit_code'] = code = ExitStatus.for_error(outcome.error_name)
        if args.json:
            print(json.dumps(report))
        return code
    spec = run_with_deep_stack(spec_from_text_sections, outcome.ltl_specification)
    run = CapabilityRun(outcome.machine, outcome.automaton, system.capabilities,
                        spec, script).run()
    report.update(run.to_dict())
    if run.violations:
        code = ExitStatus.VIOLATIONS
    elif run.outcome is None:
        code = ExitStatus.NOT_FINISHED
    else:
        code = ExitStatus.OK if run.outcome == args.expect else ExitStatus.OTHER_OUTCOME
    report['exit_code'] = code
    if args.json:
        print(json.dumps(report))
    else:
        print_capability_run(run, stream=log)
    if run.not_finished:
        print(f'execute: {run.not_finished}', file=sys.stderr)
    return code


def print_capability_run(run, stream=sys.stdout) -> None:
    print('trace:', file=stream)
    shown: list[tuple[int, Any] | None] = list(enumerate(run.steps, start=1))
    if len(shown) > 30:  # a failure retried until the step limit: its start and its end
        shown = [*shown[:20], None, *shown[-5:]]
    for entry in shown:
        if entry is None:
            print(f'  ...  ({len(run.steps) - 25} more states)', file=stream)
            continue
        index, step = entry
        print(f'  {index:3d}  {step.state:<28} {step.capability}: {step.outcome}  ({step.chosen_by})', file=stream)
    if run.violations:
        print('trace check: ' + '; '.join(run.violations), file=stream)
    elif run.outcome is not None:
        print('trace check: ok (every answer an environment move the specification allows, every next state '
              "the strategy's move)", file=stream)
    print(f'outcome: {run.outcome or "none"}', file=stream)


def _missing_flexbe_engine() -> str:
    """Why the FlexBE engine cannot run here ('' when flexbe_core imports)."""
    try:
        import flexbe_core  # noqa: F401
    except ImportError as error:
        return (f'the FlexBE engine is not installed ({error}): run `make flexbe` (FlexBE sources in '
                'FLEXBE_SOURCES) or source a ROS 2 workspace with FlexBE')
    return ''


def _synthesize_and_execute(args, system, simulator, initial_conditions, batches, report, log) -> int:
    try:
        with in_process_suite(args, 'execute_client') as (ros, client):
            session = _Session(args, ros, client, system, simulator, log)
            if len(batches) == 1:
                report.update(goals=batches[0])
                return session.run_batch(initial_conditions, batches[0], report, args.record, args.expect)
            return session.run_mission(initial_conditions, batches, report)
    except SuiteUnavailableError as error:
        print(f'execute: {error}', file=sys.stderr)
        return ExitStatus.UNAVAILABLE


class _Session:
    """Synthesis and execution of goal batches on one simulated robot (of ``system``, a RobotSystem)."""

    def __init__(self, args, ros, client, system, simulator, log):
        self.args, self.ros, self.client, self.log = args, ros, client, log
        self.system, self.simulator = system, simulator
        self._robot = None
        self.uses_ros_sim = args.ros_sim or args.engine == 'flexbe'  # FlexBE drives the node

    def robot(self):
        """The robot (and the simulator node with ``--ros-sim``), made once and kept for every batch."""
        if self._robot is None:
            if self.uses_ros_sim:
                self._robot = _ros_robot(self.ros, self.args, self.simulator)
            else:
                from atlas_sim.simulated_robot import SimulatedRobot

                self._robot = SimulatedRobot(self.simulator), None
        return self._robot

    def run_mission(self, initial_conditions, batches, report) -> int:
        """Each batch from where the previous one left the robot; stops at 3, 4 or 5 (see Exit status)."""
        from ltl_specification.initial_conditions import CURRENT

        report['batches'] = []
        for index, goals in enumerate(batches):
            batch = {'goals': goals}
            report['batches'].append(batch)
            last = index == len(batches) - 1
            print(f'=== batch {index + 1}/{len(batches)}: {", ".join(goals)}', file=self.log)
            record = str(Path(self.args.record) / f'batch{index + 1}') if self.args.record else None
            code = self.run_batch(initial_conditions if index == 0 else [CURRENT], goals, batch, record,
                                  self.args.expect if last else 'finished')
            batch['exit_code'] = code
            if code not in (ExitStatus.OK, ExitStatus.OTHER_OUTCOME):
                break
        return code

    def run_batch(self, initial_conditions, goals, report, record, expect) -> int:
        """Synthesize ``goals`` from ``initial_conditions`` (or the robot's), run and check them."""
        from argparse import Namespace

        from ltl_specification.initial_conditions import initial_conditions_in_status

        requested, source = self.initial_conditions_for(initial_conditions)
        goal = goal_from_args(Namespace(**{**vars(self.args), 'initial_conditions': requested, 'goals': goals}))
        progress = None if self.args.json else ProgressBar()
        statuses = []

        def on_feedback(status, fraction):
            statuses.append(status)
            if progress:
                progress(status, fraction)

        outcome = self.client.run(goal, feedback=on_feedback)
        if progress:
            progress.close(outcome)
        detected = next(filter(None, map(initial_conditions_in_status, statuses)), None)
        if detected is not None:  # the server read them from the robot state topic
            source, requested = detected
        report.update(initial_conditions=requested, initial_conditions_source=source)
        report['synthesis'] = {'error_name': outcome.error_name, 'error_code': outcome.error_code,
                               'message': outcome.message, 'seconds': round(outcome.seconds, 4),
                               'states': len(outcome.states)}
        if not self.args.json:
            print(f'initial conditions ({source}): {", ".join(requested)}', file=self.log)
            print_summary(outcome, stream=self.log)
        if not outcome.succeeded:
            print(f'execute: synthesis failed: {outcome.error_name}: {outcome.message}', file=sys.stderr)
            return ExitStatus.for_error(outcome.error_name)
        robot, sim_node = self.robot()
        return _execute(self.args, self.system, outcome, robot, self.simulator, goals, report, self.log, sim_node,
                        record, expect, self.ros.domain_id)

    def initial_conditions_for(self, initial_conditions) -> tuple[list[str], str]:
        """What to request, and where it comes from: 'request', 'simulator' or the server's topic.

        With ``--ros-sim`` the server reads the robot's state itself (the simulator node
        publishes it); the in-process simulator publishes nothing, so it is read here.
        """
        from ltl_specification.initial_conditions import (CURRENT, asks_for_robot_state,
                                                          initial_conditions_from_robot_state)

        if not asks_for_robot_state(initial_conditions):
            return list(initial_conditions), 'request'
        if self.uses_ros_sim:
            self.robot()  # the simulator node must be up and publishing before the server asks
            return [CURRENT], 'server'
        snapshot = self.simulator.snapshot()
        return initial_conditions_from_robot_state(snapshot['mode'], snapshot['completed_actions'],
                                                   source='the simulator'), 'simulator'


def _ros_robot(ros, args, simulator):
    """The atlas_sim node around ``simulator`` (so --record can watch it here) and its adapter."""
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
    from synthesis_manager.ros.atlas_sim_robot import RosRobot

    node = ros.add_node(AtlasSimNode, simulator=simulator,
                        parameter_overrides=[Parameter('speed', value=float(args.speed)),
                                             Parameter('state_rate', value=50.0)])
    robot = RosRobot(ros.add_node(Node, 'execute_robot'))
    robot.wait_until_ready()
    return robot, node


def _execute(args, system, outcome, robot, simulator, goals, report, log, sim_node, record, expect,
             domain_id=None) -> int:
    view = lock = None
    if record and sim_node is not None:  # the node steps physics in its own thread: render here
        view, lock = DeferredEvents(simulator, sim_node.lock), sim_node.lock
    run_machine = None
    if args.engine == 'flexbe':
        # FlexBE is no registry package: imported only when asked for
        from synthesis_manager.ros.flexbe_engine import run_on_flexbe

        run_machine = lambda _tick: run_on_flexbe(  # noqa: E731
            outcome.machine, simulator, sim_node.lock, domain_id, system,
            max_wall_time=args.max_robot_time * 10 + 60, verbose=args.verbose)
    try:
        run = run_and_check(outcome.machine, robot, simulator, system,
                            run_with_deep_stack(spec_from_text_sections, outcome.ltl_specification), goals,
                            ordered=not args.unordered, record_dir=record,
                            max_robot_time=args.max_robot_time, max_wall_time=args.max_robot_time * 10 + 60,
                            view=view, lock=lock, run_machine=run_machine)
    except ExecutionError as error:
        report.update(outcome=None, error={'code': error.code, 'item': error.item, 'message': str(error)},
                      trace=error.trace.to_dict() if error.trace else None, fallen=simulator.has_fallen())
        print(f'execute: {error}', file=sys.stderr)
        return ExitStatus.NOT_FINISHED
    result, check = run.result, run.check
    fallen = result.fallen or simulator.has_fallen()
    report.update(outcome=result.outcome, trace=result.trace.to_dict(), trace_check=check.to_dict(),
                  fallen=fallen, robot_time=round(result.duration, 3), wall_time=round(run.wall_seconds, 3),
                  min_pelvis_height=round(result.min_pelvis_height, 3))
    if record:
        report['timeline'] = str(run.timeline)
        report['frames'] = [str(p) for p in run.frames]
    if not args.json:
        print_run(result, check, fallen, run.wall_seconds, stream=log)
        if record:
            print(f'recorded {len(run.frames)} frames and {report["timeline"]}', file=log)
    if check.violations or fallen:
        return ExitStatus.VIOLATIONS
    return ExitStatus.OK if result.outcome == expect else ExitStatus.OTHER_OUTCOME


def print_run(run, check, fallen: bool, wall: float, stream=sys.stdout) -> None:
    print('trace:', file=stream)
    for step in run.trace.steps:
        results = ', '.join(f"{r['capability']} {r['outcome']}" + (' (abandoned)' if r['abandoned'] else '')
                            + (f" ({r['reason']})" if r['outcome'] != 'completed' and r.get('reason') else '')
                            for r in step.results) or '-'
        print(f'  {step.index:3d}  {step.entered_at:7.2f}-{step.ended_at:7.2f} s  {step.state:<28} '
              f'[{", ".join(step.activated)}]  {results}  => {step.state_outcome} -> {step.transition}',
              file=stream)
    print(check.summary(), file=stream)
    speed = run.duration / wall if wall > 0 else float('inf')
    print(f'outcome: {run.outcome}  (robot time {run.duration:.2f} s in {wall:.2f} s wall, {speed:.1f}x; '
          f'fallen: {"yes" if fallen else "no"}; lowest pelvis {run.min_pelvis_height:.2f} m)', file=stream)
