"""``behavior-synthesis start-behavior NAME``: start an installed FlexBE behavior on a running
onboard engine (``flexbe_onboard``), wait for it and say how it ended.

It sends what FlexBE's ``be_launcher`` sends (a ``flexbe_msgs/BehaviorSelection`` on
``flexbe/start_behavior``: the key from flexbe_core's BehaviorLibrary, the id the adler32 of the
behavior's source), then follows the engine's ``flexbe/status`` for that behavior id and its
``flexbe/log``. ``be_launcher`` stops listening once it has sent: a behavior whose preparation
fails (a missing import) is dropped by the engine with an ERROR status and a log line, and
``be_launcher`` goes on showing READY. Here that ends the command within seconds, printing the
engine's reason, with a non-zero status.

Needs FlexBE (flexbe_core, flexbe_msgs) and the behavior's package found as the onboard engine
finds it: the workspace sourced, or its prefix on AMENT_PREFIX_PATH and PYTHONPATH.
"""

from __future__ import annotations

import contextlib
import io
import re
import sys
import threading
import time
import zlib
from pathlib import Path

from respec.vocabulary.errors import ExitStatus, exit_status_help

ENGINE_WAIT = 30.0   # seconds for an onboard engine to subscribe to flexbe/start_behavior
PREPARATION_WAIT = 60.0  # seconds from the selection to the engine's first word on it
_NAME_ERROR = re.compile(r"name '([A-Za-z_][A-Za-z0-9_]*)' is not defined")


def add_arguments(parser):
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE, ExitStatus.TIMED_OUT,
                                     ExitStatus.UNAVAILABLE, ExitStatus.OTHER_OUTCOME)
    parser.add_argument('name', help="the behavior's name, as in its manifest (e.g. 'Look Down Pickup Object')")
    parser.add_argument('--autonomy', type=int, default=3, choices=range(0, 4), metavar='0-3',
                        help='autonomy level: 0 off, 1 low, 2 high, 3 full (default: 3, as be_launcher -a 3)')
    parser.add_argument('--timeout', type=float, default=600.0,
                        help='seconds to wait for the behavior to end once started')
    parser.add_argument('--expect', metavar='OUTCOME',
                        help=f'exit {int(ExitStatus.OTHER_OUTCOME)} unless the behavior ends in this outcome')
    parser.add_argument('--wait-for', action='append', default=[], metavar='ACTION',
                        help="also wait for this action server before starting (repeatable), e.g. the robot's "
                             'atlas_sim/execute and the operator\'s flexbe/behavior_input: a behavior started '
                             'earlier fails its first state that calls one')
    parser.add_argument('--namespace', default='', metavar='NS',
                        help="the onboard engine's namespace (its flexbe/... topics), e.g. /robot1")


def name_error_hint(reason: str) -> str:
    """A sentence for an engine reason that is a Python NameError (the engine logs only its text)."""
    found = _NAME_ERROR.search(reason)
    if not found:
        return ''
    return (f"NameError: {found.group(0)}: the behavior's code uses {found.group(1)} without importing it "
            '(a behavior saved by the FlexBE WebUI for this engine needs its Manual Imports; README, '
            '"Use it from FlexBE")')


class OnboardWatch:
    """The engine's status and log topics as one node sees them."""

    def __init__(self, node):
        from flexbe_msgs.msg import BEStatus, BehaviorLog, BehaviorSelection

        self.node, self.lock = node, threading.RLock()  # wait() holds it while errors_since() takes it
        self.statuses, self.logs = [], []
        node.create_subscription(BEStatus, 'flexbe/status', lambda m: self._keep(self.statuses, m), 100)
        node.create_subscription(BehaviorLog, 'flexbe/log', lambda m: self._keep(self.logs, m), 100)
        self.selection = node.create_publisher(BehaviorSelection, 'flexbe/start_behavior', 10)

    def _keep(self, messages, message):
        with self.lock:
            messages.append(message)

    def wait(self, condition, timeout: float):
        """``condition()``'s first true value within ``timeout`` seconds, else None."""
        deadline = time.monotonic() + timeout
        while True:
            with self.lock:
                found = condition()
            if found or time.monotonic() >= deadline:
                return found
            time.sleep(0.05)

    def status_of(self, behavior_id: int, codes):
        return next((s for s in self.statuses if s.behavior_id == behavior_id and s.code in codes), None)

    def errors_since(self, first: int) -> list[str]:
        from flexbe_msgs.msg import BehaviorLog

        with self.lock:  # each once: the engine's lines may arrive twice (its Logger publishes per handler)
            return list(dict.fromkeys(m.text.strip() for m in self.logs[first:] if m.status_code == BehaviorLog.ERROR))


def action_served(node, name: str) -> bool:
    """An action server ``name`` (absolute) is up: its status topic has a publisher."""
    return node.count_publishers(f'{name}/_action/status') > 0


def selection_for(node, name: str):
    """The BehaviorSelection be_launcher sends for ``name``; LookupError naming what is known."""
    from flexbe_core import BehaviorLibrary
    from flexbe_msgs.msg import BehaviorSelection

    with contextlib.redirect_stdout(io.StringIO()):  # the library prints a table of every behavior it found
        library = BehaviorLibrary(node)
        key, entry = library.find_behavior(name)
    if entry is None:
        known = sorted(entry['name'] for entry in library._behavior_lib.values())  # noqa: SLF001 - listed nowhere else
        raise LookupError(f'no installed behavior is called {name!r} (found: {", ".join(known) or "none"}; '
                          'is its workspace sourced, or its prefix on AMENT_PREFIX_PATH and PYTHONPATH?)')
    source = Path(library.get_sourcecode_filepath(key)).read_text(encoding='utf-8')
    return BehaviorSelection(behavior_key=key, behavior_id=zlib.adler32(source.encode()) & 0x7fffffff)


def run(args) -> int:
    try:
        from flexbe_msgs.msg import BEStatus
    except ImportError as error:
        print(f'start-behavior: FlexBE is not importable ({error}): source your FlexBE workspace '
              '(or /opt/ros/jazzy), or run `make flexbe`', file=sys.stderr)
        return ExitStatus.UNAVAILABLE
    from rclpy.node import Node

    from synthesis_manager.ros.harness import RosHarness, environment_domain_id
    from synthesis_manager.ros.namespaces import namespace_placement

    def say(text):
        print(f'start-behavior: {text}', file=sys.stderr, flush=True)

    with RosHarness(domain_id=environment_domain_id()) as ros:
        node = ros.add_node(Node, 'behavior_synthesis_start_behavior', **namespace_placement(args.namespace))
        watch = OnboardWatch(node)
        try:
            selection = selection_for(node, args.name)
        except LookupError as error:
            say(str(error))
            return ExitStatus.FAILED
        selection.autonomy_level = args.autonomy
        topic = node.resolve_topic_name('flexbe/start_behavior')
        say(f'waiting for the onboard engine on {topic}{" and " + ", ".join(args.wait_for) if args.wait_for else ""}…')
        if not watch.wait(lambda: watch.selection.get_subscription_count() > 0, ENGINE_WAIT):
            say(f'no onboard engine listens on {topic} after {ENGINE_WAIT:g} s (start it with '
                '`ros2 run flexbe_onboard start_behavior`; same ROS_DOMAIN_ID?)')
            return ExitStatus.UNAVAILABLE
        for action in args.wait_for:
            name = node.resolve_topic_name(action)
            if not watch.wait(lambda: action_served(node, name), ENGINE_WAIT):
                say(f'no {name} action server after {ENGINE_WAIT:g} s')
                return ExitStatus.UNAVAILABLE
        first_log = len(watch.logs)
        watch.selection.publish(selection)
        behavior_id = selection.behavior_id

        started = watch.wait(lambda: watch.status_of(behavior_id, (BEStatus.STARTED, BEStatus.ERROR,
                                                                   BEStatus.FAILED, BEStatus.FINISHED)),
                             PREPARATION_WAIT)
        if started is None:
            say(f'the onboard engine said nothing about {args.name!r} within {PREPARATION_WAIT:g} s')
            return ExitStatus.TIMED_OUT
        if started.code == BEStatus.ERROR:
            # the engine logs its reason just before the status: give the log a moment to arrive
            watch.wait(lambda: watch.errors_since(first_log), 2.0)
            reasons = watch.errors_since(first_log) or ['(no reason on flexbe/log)']
            say(f'the onboard engine could not prepare {args.name!r}:')
            for reason in reasons:
                print('  ' + reason.replace('\n', '\n  '), file=sys.stderr)
            hint = next(filter(None, map(name_error_hint, reasons)), '')
            if hint:
                say(hint)
            return ExitStatus.FAILED
        say(f'{args.name!r} started (behavior id {behavior_id})')
        ended = watch.wait(lambda: watch.status_of(behavior_id, (BEStatus.FAILED, BEStatus.FINISHED)), args.timeout)
        if ended is None:
            say(f'{args.name!r} still runs after {args.timeout:g} s')
            return ExitStatus.TIMED_OUT
        if ended.code == BEStatus.FAILED:
            watch.wait(lambda: watch.errors_since(first_log), 2.0)
            say(f'{args.name!r} failed while running:')
            for reason in watch.errors_since(first_log) or ['(no reason on flexbe/log)']:
                print('  ' + reason.replace('\n', '\n  '), file=sys.stderr)
            return ExitStatus.FAILED
        outcome = ended.args[0] if ended.args else ''
        print(outcome)
        if args.expect and outcome != args.expect:
            say(f'expected {args.expect!r}, the behavior ended {outcome!r}')
            return ExitStatus.OTHER_OUTCOME
        return ExitStatus.OK
