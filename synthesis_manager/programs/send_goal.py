"""``behavior-synthesis send-goal``: send one goal to a running suite, show progress and the result."""

from __future__ import annotations

import json
import sys
import threading
from pathlib import Path

from rclpy.node import Node

from respec.vocabulary.errors import CodedError, ExitStatus, exit_status_help, quoted
from respec.vocabulary.naming import parse_names
from respec.nesting import run_with_deep_stack
from respec.parsing import parse_structuredslugs
from sm_generation.instantiation import count_states
from respec.untrusted import read_bounded_file
from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.limits import MAX_MESSAGE_BYTES
from synthesis_manager.requests import DEFAULT_SYSTEM, InvalidRequestError, resolve_system
from synthesis_manager.ros.harness import RosHarness, environment_domain_id
from synthesis_manager.ros.namespaces import namespace_placement
from synthesis_manager.summary import generated_summary, spec_size, state_machine_tree


# The paper's task, which a command runs when no --goals are given (and says so).
DEMO_GOALS = 'look_down,pickup_object'


def add_goal_arguments(parser, with_options: bool = True):
    """The task description shared by send-goal, demo and execute."""
    parser.add_argument('--system', default='atlas', help='robot system (a config/<system>.yaml)')
    parser.add_argument('--initial-conditions', default=None,
                        help="comma-separated initial conditions (default: the system's own: its initial_mode, "
                             "or a capability robot's specification; '' or current: the robot's state)")
    parser.add_argument('--goals', help='comma-separated goals, in order (default: the paper\'s demo task, '
                        f'{DEMO_GOALS}, which is said on stderr)')
    parser.add_argument('--sm-outcomes', default='finished,failed',
                        help='state machine outcomes: finished,failed or finished (retry on failure)')
    parser.add_argument('--unordered', action='store_true', help='goals may be achieved in any order')
    parser.add_argument('--name', default='', help='behavior name (names the byproduct files)')
    if with_options:
        stop = parser.add_mutually_exclusive_group()
        stop.add_argument('--compile-only', action='store_true', help='stop after LTL compilation')
        stop.add_argument('--synthesis-only', metavar='SPEC',
                          help='synthesize this .structuredslugs or LTLSpecification .json file')
        stop.add_argument('--ltl-steps-only', action='store_true', help='stop at the automaton')


def add_arguments(parser):
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE, ExitStatus.TIMED_OUT,
                                     ExitStatus.UNAVAILABLE)
    add_goal_arguments(parser)
    parser.add_argument('--action', choices=('behavior_synthesis', 'flexbe_synthesis'),
                        default='behavior_synthesis',
                        help="the server's interface: the original BehaviorSynthesis or CNU's FlexBESynthesis")
    parser.add_argument('--timeout', type=float, default=120.0, help='seconds to wait for the result')
    add_robot_namespace_argument(parser)
    parser.add_argument('--json', action='store_true', help='print the result as one JSON object')
    parser.add_argument('-o', '--output', help='also write the JSON result to this file')


def add_robot_namespace_argument(parser):
    """A client's ``--namespace``: the robot whose server (and so whose state) it asks."""
    parser.add_argument('--namespace', default='', metavar='NS',
                        help="the robot's ROS namespace, e.g. /robot1: its server's <NS>/behavior_synthesis "
                             '(default: the server outside any namespace)')


def fill_default_initial_conditions(args) -> None:
    """No --initial-conditions: the system's own (``RobotSystem.default_initial_conditions``),
    read from the system file as this command finds it (its --config-dir); a system it cannot
    read here (a server's own) gets none, and the server answers for it."""
    if args.initial_conditions is not None:
        return
    from respec.robot import robot_system

    system = resolve_system(args.system, getattr(args, 'default_system', '') or DEFAULT_SYSTEM)
    try:
        args.initial_conditions = ','.join(robot_system(system, getattr(args, 'config_dir', None) or None)
                                           .default_initial_conditions)
    except CodedError:
        args.initial_conditions = ''


def use_demo_goals_unless_given(args, command: str, stream=None) -> None:
    """No --goals: the paper's demo task, said once so that nobody wonders where it came from."""
    if args.goals is not None:
        return
    args.goals = DEMO_GOALS
    if command != 'demo' and not getattr(args, 'synthesis_only', None):
        print(f'{command}: no --goals given: using the demo task --initial-conditions {args.initial_conditions} '
              f'--goals {DEMO_GOALS}', file=stream or sys.stderr)  # sys.stderr as it is now


def goal_from_args(args):
    option, spec = None, None
    if getattr(args, 'compile_only', False):
        option = 'ltl_compilation_only'
    elif getattr(args, 'ltl_steps_only', False):
        option = 'ltl_steps_only'
    elif getattr(args, 'synthesis_only', None):
        option, spec = 'ltl_synthesis_only', read_spec_file(args.synthesis_only)
    if getattr(args, 'action', '') == 'flexbe_synthesis':
        if spec is not None:
            raise InvalidRequestError('--synthesis-only needs --action behavior_synthesis (FlexBESynthesis '
                                 'goals carry no specification)')
        return make_flexbe_goal(args.system, parse_names(args.initial_conditions), parse_names(args.goals),
                                parse_names(args.sm_outcomes), option=option, name=args.name,
                                timeout=getattr(args, 'timeout', 0.0), unordered=args.unordered)
    return make_goal(args.system, parse_names(args.initial_conditions), parse_names(args.goals),
                     parse_names(args.sm_outcomes), option=option, name=args.name,
                     ltl_specification=spec, unordered=args.unordered,
                     timeout=getattr(args, 'timeout', 0.0))


def read_spec_file(path: str) -> dict:
    """A complete specification from a .structuredslugs file or an LTLSpecification JSON dict
    (at most what a goal may carry, MAX_MESSAGE_BYTES); InvalidRequestError naming the file
    when it is not one."""
    try:
        text = read_bounded_file(path, MAX_MESSAGE_BYTES)
        if path.endswith('.json'):
            return json.loads(text)
    except (OSError, ValueError, RecursionError) as error:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        problem = 'JSON nested too deeply' if isinstance(error, RecursionError) else error
        raise InvalidRequestError(f'cannot read the specification file {path}: {quoted(str(problem), 200)}',
                                  item=path) from None
    # Its formulas may nest MAX_FORMULA_NESTING deep: read and printed on a deep stack.
    return run_with_deep_stack(lambda: parse_structuredslugs(text, filename=path).to_text_sections())


SERVER_WAIT = 10.0  # seconds to wait for the action server to appear
# Seconds an interrupted send-goal waits for its cancelled goal's result (it exits within 3 s).
CANCEL_GRACE = 2.0


class ProgressBar:
    """A one-line progress bar on stderr driven by the action's feedback.

    Feedback and result travel apart (a topic and a service), so the server's last feedback,
    sent just before the result, can reach the client after it: the bar's full line is drawn
    from the result (``close(outcome)``), the same whichever comes first, and feedback after
    that is ignored."""

    def __init__(self, stream=sys.stderr, width: int = 30):
        self.stream, self.width = stream, width
        self.closed = False
        self._lock = threading.Lock()  # feedback comes on the executor's thread, close on the caller's

    def __call__(self, status: str, progress: float):
        with self._lock:
            if not self.closed and progress < 1.0:
                self._draw(status, progress)

    def _draw(self, status: str, progress: float):
        filled = int(round(progress * self.width))
        self.stream.write(f'\r[{"#" * filled}{"." * (self.width - filled)}] {progress:4.0%} {status:<60.60}')
        self.stream.flush()

    def close(self, outcome=None):
        with self._lock:
            if self.closed:
                return
            if outcome is not None and outcome.succeeded:
                self._draw(generated_summary(outcome.states) if outcome.states else 'Finished', 1.0)
            self.closed = True
            self.stream.write('\n')
            self.stream.flush()


def print_summary(outcome, stream=sys.stdout):
    print(f'result: {outcome.error_name} ({outcome.error_code}) in {outcome.seconds * 1000:.0f} ms',
          file=stream)
    if outcome.message:
        print(f'message: {outcome.message}', file=stream)
    if outcome.ltl_specification:
        print(f'specification: {spec_size(outcome.ltl_specification)}', file=stream)
    if outcome.automaton.get('states'):
        print(f"automaton: {len(outcome.automaton['states'])} states", file=stream)
    if outcome.states:
        print(f'state machine: {count_states(outcome.states)} states '
              f'({len(outcome.states)} StateInstantiation entries):', file=stream)
        print(state_machine_tree(outcome.machine), file=stream)


def run(args) -> int:
    try:
        goal = goal_from_args(args)
    except (OSError, ValueError, CodedError) as error:
        print(f'send-goal: cannot read the request: {error}', file=sys.stderr)
        return ExitStatus.USAGE

    with RosHarness(domain_id=environment_domain_id()) as ros:
        node = ros.add_node(Node, 'behavior_synthesis_client', **namespace_placement(args.namespace))
        action = node.resolve_service_name(args.action)  # the absolute name the client asks
        print(f'send-goal: waiting for {action}…', file=sys.stderr, flush=True)
        client = SynthesisClient(node, args.action)
        if not client.wait_for_server(timeout=SERVER_WAIT):
            print(f'send-goal: no {action} action server after {SERVER_WAIT:g} s (start one with '
                  '`behavior-synthesis serve` or `behavior-synthesis gui`)', file=sys.stderr)
            return ExitStatus.UNAVAILABLE
        progress = None if args.json else ProgressBar()
        cancel = threading.Event()
        outcome_box = {}
        finished = threading.Event()

        def wait_for_outcome():
            try:
                outcome_box['outcome'] = client.run(goal, feedback=progress, cancel=cancel,
                                                    timeout=args.timeout + 30)
            except Exception as error:  # noqa: BLE001 - handed to the waiting thread, which reports it
                outcome_box['error'] = error
            finally:
                finished.set()

        # Wait on an Event, not Thread.join: an interrupted join can lose track of the thread.
        threading.Thread(target=wait_for_outcome, daemon=True).start()
        interrupted = False
        try:
            while not finished.wait(0.1):
                pass
        except KeyboardInterrupt:  # Ctrl-C/SIGTERM cancel the goal; its result shows the cancel
            interrupted = True
            cancel.set()
            finished.wait(CANCEL_GRACE)
        if progress:
            progress.close(outcome_box.get('outcome'))
    outcome = outcome_box.get('outcome')
    if outcome is None:
        print(f"send-goal: no result: {outcome_box.get('error', 'interrupted')}", file=sys.stderr)
    else:
        if args.output:
            Path(args.output).write_text(json.dumps(outcome.to_dict(), indent=1))
        if args.json:
            print(json.dumps(outcome.to_dict()))
        else:
            print_summary(outcome)
    if interrupted:
        raise KeyboardInterrupt  # the command line exits with 128 + the signal's number
    if outcome is None:
        return ExitStatus.FAILED
    return ExitStatus.for_error(outcome.error_name)
