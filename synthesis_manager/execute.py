"""``behavior-synthesis execute``: synthesize a behavior, run it on the simulated ATLAS, check the run.

The task goes through the ``/behavior_synthesis`` action with the suite's nodes running
in-process (as ``demo`` does); the returned state machine runs on the MuJoCo simulator
(in-process, or with ``--ros-sim`` through the ``atlas_sim`` node over ROS) and the
executed trace is checked against the returned specification.

    behavior-synthesis execute --initial-conditions stand_prep --goals look_down,pickup_object
    behavior-synthesis execute --goals pickup_object --fail pickup_object --expect failed
    behavior-synthesis execute --goals pickup_object --sm-outcomes finished --fail-first pickup_object:2
    behavior-synthesis execute --json --record out/run      # PNG key frames + timeline.png
    behavior-synthesis execute --engine flexbe --goals look_down,pickup_object   # on flexbe_core

With ``--engine flexbe`` the machine is exported as a FlexBE behavior and run by the real
FlexBE engine (``synthesis_manager.ros.flexbe_engine``), its states driving the simulator
node over ROS; the report is the same.

Exit status:
  0  the run ended in the expected SM outcome (``--expect``, default ``finished``), the
     trace check found no violation and the robot did not fall;
  1  the run ended in another SM outcome (trace clean, robot standing);
  2  bad command line (e.g. a malformed ``--fail-first``);
  3  synthesis failed (the action's error code is printed);
  4  the trace check found violations, or the robot fell;
  5  the run could not finish (robot-time limit, a state the executive cannot run, ...).
"""

from __future__ import annotations

import collections
import contextlib
import json
import os
import sys
import time
from pathlib import Path

from synthesis_manager.send_goal import ProgressBar, add_goal_arguments, goal_from_args, print_summary
from synthesis_manager.suite import SuiteUnavailable, add_suite_arguments, in_process_suite

EXIT_OK, EXIT_OTHER_OUTCOME, EXIT_USAGE, EXIT_SYNTHESIS, EXIT_VIOLATIONS, EXIT_EXECUTION = 0, 1, 2, 3, 4, 5


EXIT_STATUS_HELP = __doc__[__doc__.index('Exit status:'):]


def add_arguments(parser):
    import argparse

    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = EXIT_STATUS_HELP
    add_goal_arguments(parser, with_options=False)
    parser.set_defaults(name='execute')
    add_suite_arguments(parser)
    group = parser.add_argument_group('execution')
    group.add_argument('--fail', action='append', default=[], metavar='ACTION[,ACTION]',
                       help='capabilities that always fail (repeatable)')
    group.add_argument('--fail-first', action='append', default=[], metavar='ACTION:K',
                       help='the first K attempts of ACTION fail (repeatable, comma-separated)')
    group.add_argument('--seed', type=int, default=None, help='seed of probabilistic faults')
    group.add_argument('--expect', default='finished', metavar='OUTCOME',
                       help='the SM outcome the run should end in (default: finished)')
    group.add_argument('--engine', choices=('ours', 'flexbe'), default='ours',
                       help='who runs the state machine: our fast executive (default) or the real FlexBE '
                            'engine (flexbe_core, e.g. from `make flexbe`; implies --ros-sim)')
    group.add_argument('--ros-sim', action='store_true',
                       help='run the simulator as the atlas_sim node and drive it over ROS')
    group.add_argument('--speed', type=float, default=10.0,
                       help='with --ros-sim: sim seconds per wall second (0: as fast as possible)')
    group.add_argument('--max-robot-time', type=float, default=300.0, help='robot seconds before giving up')
    group.add_argument('--json', action='store_true',
                       help='print {"outcome", "trace", "trace_check", "fallen", ...} as one JSON object')
    group.add_argument('--record', metavar='DIR',
                       help='save PNG frames of key moments and timeline.png in DIR')


def run(args) -> int:
    from atlas_sim.executor import FaultSpecError, InitialConditionError, make_simulator, parse_faults
    from respec.systems import SystemConfigError
    from respec.naming import parse_names

    if args.engine == 'flexbe':
        problem = _flexbe_usage_problem(args)
        if problem:
            print(f'execute: {problem}', file=sys.stderr)
            return EXIT_USAGE
    if args.record:
        os.environ.setdefault('MUJOCO_GL', 'egl')  # before anything imports mujoco
    initial_conditions = parse_names(args.initial_conditions)
    goals = parse_names(args.goals)
    try:  # the simulator first: a bad fault or start is a usage error, found before synthesis
        faults = parse_faults(parse_names(args.fail), parse_names(args.fail_first))
        simulator = make_simulator(args.system, args.config_dir or None, initial_conditions, faults, args.seed)
    except (FaultSpecError, InitialConditionError, SystemConfigError) as error:
        print(f'execute: {error}', file=sys.stderr)
        return EXIT_USAGE
    log = sys.stderr if args.json else sys.stdout
    report = {'system': args.system, 'initial_conditions': initial_conditions, 'goals': goals,
              'faults': faults}
    try:
        code = _synthesize_and_execute(args, simulator, goals, report, log)
    except KeyboardInterrupt:
        print('\nexecute: interrupted', file=sys.stderr)
        return 130
    report['exit_code'] = code
    if args.json:
        print(json.dumps(report))
    return code


def _flexbe_usage_problem(args) -> str:
    if args.record:
        return '--record is not available with --engine flexbe'
    try:
        import flexbe_core  # noqa: F401
    except ImportError as error:
        return (f'the FlexBE engine is not installed ({error}): run `make flexbe` (FlexBE sources in '
                'FLEXBE_SOURCES) or source a ROS 2 workspace with FlexBE')
    return ''


def _synthesize_and_execute(args, simulator, goals, report, log) -> int:
    try:
        with in_process_suite(args, 'execute_client') as (ros, client):
            return _run_in_suite(args, ros, client, simulator, goals, report, log)
    except SuiteUnavailable as error:
        print(f'execute: {error}', file=sys.stderr)
        return EXIT_SYNTHESIS


def _run_in_suite(args, ros, client, simulator, goals, report, log) -> int:
    progress = None if args.json else ProgressBar()
    outcome = client.run(goal_from_args(args), feedback=progress)
    if progress:
        progress.close()
    report['synthesis'] = {'error_name': outcome.error_name, 'error_code': outcome.error_code,
                           'message': outcome.message, 'seconds': round(outcome.seconds, 4),
                           'states': len(outcome.states)}
    if not args.json:
        print_summary(outcome, stream=log)
    if not outcome.succeeded:
        print(f'execute: synthesis failed: {outcome.error_name}: {outcome.message}', file=sys.stderr)
        return EXIT_SYNTHESIS
    sim_node = None
    if args.ros_sim or args.engine == 'flexbe':
        robot, sim_node = _ros_robot(ros, args, simulator)
    else:
        from atlas_sim.executor import SimulatedRobot

        robot = SimulatedRobot(simulator)
    return _execute(args, outcome, robot, simulator, goals, report, log, sim_node, ros.domain_id)


def _ros_robot(ros, args, simulator):
    """The atlas_sim node around ``simulator`` (so --record can watch it here) and its adapter."""
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
    from synthesis_manager.nodes.atlas_sim_robot import RosRobot

    node = ros.add_node(AtlasSimNode, simulator=simulator,
                        parameter_overrides=[Parameter('speed', value=float(args.speed)),
                                             Parameter('state_rate', value=50.0)])
    robot = RosRobot(ros.add_node(Node, 'execute_robot'))
    robot.wait_until_ready()
    return robot, node


def _execute(args, outcome, robot, simulator, goals, report, log, sim_node=None, domain_id=None) -> int:
    from atlas_sim.executor import ExecutionError, execute_state_machine
    from atlas_sim.trace_check import check_trace
    from respec.parsing import spec_from_text_sections

    spec = spec_from_text_sections(outcome.ltl_specification)
    recorder, on_tick = None, None
    if args.record:
        from atlas_sim.rendering import KeyFrameRecorder

        if sim_node is None:
            recorder = KeyFrameRecorder(simulator, Path(args.record) / 'frames', width=480, height=360)
        else:  # the node steps physics in its own thread: render here, under its lock
            view = DeferredEvents(simulator, sim_node.lock)
            recorder = KeyFrameRecorder(view, Path(args.record) / 'frames', width=480, height=360)
            on_tick = lambda robot: view.replay()  # noqa: E731
    started = time.monotonic()
    try:
        if args.engine == 'flexbe':
            from synthesis_manager.ros.flexbe_engine import run_on_flexbe

            run = run_on_flexbe(outcome.states, simulator, sim_node.lock, domain_id, args.system,
                                args.config_dir or None, max_wall_time=args.max_robot_time * 10 + 60)
        else:
            run = execute_state_machine(outcome.states, robot, args.system, args.config_dir or None,
                                        max_robot_time=args.max_robot_time,
                                        max_wall_time=args.max_robot_time * 10 + 60, on_tick=on_tick)
    except ExecutionError as error:
        report.update(outcome=None, error={'code': error.code, 'item': error.item, 'message': str(error)},
                      trace=error.trace.to_dict() if error.trace else None, fallen=simulator.has_fallen())
        print(f'execute: {error}', file=sys.stderr)
        return EXIT_EXECUTION
    finally:
        if recorder:
            if on_tick:
                on_tick(robot)
            with getattr(sim_node, 'lock', contextlib.nullcontext()):
                recorder.capture('end')
            recorder.close()
    wall = time.monotonic() - started
    check = check_trace(run.trace, spec, goals=goals, ordered=not args.unordered)
    fallen = run.fallen or simulator.has_fallen()
    report.update(outcome=run.outcome, trace=run.trace.to_dict(), trace_check=check.to_dict(), fallen=fallen,
                  robot_time=round(run.duration, 3), wall_time=round(wall, 3),
                  min_pelvis_height=round(run.min_pelvis_height, 3))
    if args.record:
        from atlas_sim.timeline import plot_timeline

        title = f'{", ".join(goals)}: {run.outcome}'
        report['timeline'] = str(plot_timeline(run.trace, Path(args.record) / 'timeline.png', title))
        report['frames'] = [str(p) for p in recorder.paths]
    if not args.json:
        print_run(run, check, fallen, wall, stream=log)
        if args.record:
            print(f'recorded {len(recorder.paths)} frames and {report["timeline"]}', file=log)
    if check.violations or fallen:
        return EXIT_VIOLATIONS
    return EXIT_OK if run.outcome == args.expect else EXIT_OTHER_OUTCOME


class DeferredEvents:
    """A simulator view for ``KeyFrameRecorder`` when another thread steps the simulator.

    OpenGL contexts belong to the thread that made them, so the simulator's events are
    queued in the stepping thread and replayed (rendered) in this one under ``lock``; frames
    show the robot a poll period after the event, named with the event's sim time.
    """

    def __init__(self, simulator, lock):
        self.simulator, self.lock = simulator, lock
        self.physics = simulator.physics
        self.time = simulator.time
        self._listeners, self._queue = [], collections.deque()
        simulator.add_listener(self._enqueue)

    def _enqueue(self, event: str, request) -> None:
        self._queue.append((event, request, self.simulator.time))

    def add_listener(self, listener) -> None:
        self._listeners.append(listener)

    def remove_listener(self, listener) -> None:
        self._listeners.remove(listener)
        if not self._listeners:
            self.simulator.remove_listener(self._enqueue)

    def replay(self) -> None:
        while self._queue:
            event, request, self.time = self._queue.popleft()
            with self.lock:
                for listener in list(self._listeners):
                    listener(event, request)
        self.time = self.simulator.time


def print_run(run, check, fallen: bool, wall: float, stream=sys.stdout) -> None:
    print('trace:', file=stream)
    for step in run.trace.steps:
        results = ', '.join(f"{r['capability']} {r['outcome']}" + (' (abandoned)' if r['abandoned'] else '')
                            for r in step.results) or '-'
        print(f'  {step.index:3d}  {step.entered_at:7.2f}-{step.ended_at:7.2f} s  {step.state:<28} '
              f'[{", ".join(step.activated)}]  {results}  => {step.state_outcome} -> {step.transition}',
              file=stream)
    print(check.summary(), file=stream)
    speed = run.duration / wall if wall > 0 else float('inf')
    print(f'outcome: {run.outcome}  (robot time {run.duration:.2f} s in {wall:.2f} s wall, {speed:.1f}x; '
          f'fallen: {"yes" if fallen else "no"}; lowest pelvis {run.min_pelvis_height:.2f} m)', file=stream)
