"""``behavior-synthesis``: the suite's command line (there is no ``ros2`` command on PyPI).

Each subcommand lives in the package that owns it and provides ``add_arguments(parser)``
and ``run(args) -> int``; modules are imported only when their subcommand is built, so
``--help`` stays fast.

SIGTERM stops a command as Ctrl-C (SIGINT) does: a client cancels its goal, an in-process
suite or a server (``serve``, ``gui``) shuts down, and the command exits with 128 + the
signal's number (130, 143), as README's status table and every ``--help`` say.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys

# name -> (module providing add_arguments/run, one-line help)
SUBCOMMANDS = {
    'demo': ('synthesis_manager.programs.demo', "run the paper's task end to end and write the artifacts"),
    'serve': ('synthesis_manager.programs.serve', 'run the synthesis suite until SIGINT/SIGTERM'),
    'send-goal': ('synthesis_manager.programs.send_goal', 'send a goal to /behavior_synthesis and show the result'),
    'compile': ('ltl_specification.cli', 'compile a task into a GR(1) specification (no ROS)'),
    'repair': ('ltl_specification.repair_cli', 'propose verified changes that make a refused task possible (no ROS)'),
    'generate-sm': ('sm_generation.cli', 'turn an automaton into a FlexBE state machine (no ROS)'),
    'execute': ('synthesis_manager.programs.execute', 'synthesize a behavior and run it on the simulated robot (ATLAS, or a capability robot)'),
    'export-behavior': ('synthesis_manager.programs.export_behavior', 'synthesize a behavior and write it as a FlexBE '
                        'behavior package'),
    'gui': ('synthesis_manager.programs.gui', 'serve the synthesis web GUI on 127.0.0.1'),
    'start-behavior': ('synthesis_manager.programs.start_behavior', 'start an installed FlexBE behavior on the onboard '
                       'engine and say how it ended'),
}

# Commands running nodes for others, which take standard ROS arguments after --ros-args.
COMMANDS_WITH_ROS_ARGUMENTS = ('serve',)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Every option's help ends with its default (unless it says it already, or has none)."""

    def _get_help_string(self, action):
        text = action.help or ''
        if action.option_strings and '%(default)' not in text and '(default' not in text \
                and action.default not in (None, False, '', [], argparse.SUPPRESS):
            text += ' (default: %(default)s)'
        return text


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='behavior-synthesis',
        description='Reactive high-level behavior synthesis: goals -> GR(1) LTL -> FlexBE state machine.')
    subparsers = parser.add_subparsers(dest='command', metavar='COMMAND')
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        subparser = subparsers.add_parser(name, help=help_text, description=help_text,
                                          formatter_class=HelpFormatter)
        if only in (None, name):
            module = importlib.import_module(module_name)
            module.add_arguments(subparser)
            subparser.set_defaults(run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    # Import only the module of the requested subcommand (fast start, isolated failures).
    command = next((word for word in argv if word in SUBCOMMANDS), None)
    parser = build_parser(only=command or '')
    argv, ros_args = split_ros_arguments(argv)
    args = parser.parse_args(argv)
    if ros_args and command not in COMMANDS_WITH_ROS_ARGUMENTS:
        parser.error(f'{command or "this command"} takes no --ros-args (a client picks its robot with '
                     '--namespace)')
    args.ros_args = ros_args
    if not getattr(args, 'run', None):
        parser.print_help()
        return 0 if not argv or '-h' in argv or '--help' in argv else 2
    if hasattr(args, 'initial_conditions') and hasattr(args, 'sm_outcomes') and args.initial_conditions is None:
        from synthesis_manager.programs.send_goal import fill_default_initial_conditions

        fill_default_initial_conditions(args)  # a command of the suite's task (send-goal, demo, execute, ...)
    if getattr(args, 'goals', '') is None:
        from synthesis_manager.programs.send_goal import use_demo_goals_unless_given

        use_demo_goals_unless_given(args, args.command)
    with stop_signals_interrupt() as received:
        try:
            status = args.run(args)
        except KeyboardInterrupt:
            print(f'\nbehavior-synthesis {args.command}: interrupted', file=sys.stderr)
            return 128 + (received[-1] if received else signal.SIGINT)
    # a server ends its run normally once a signal has stopped it: the signal still says why
    return 128 + received[-1] if received else status


def split_ros_arguments(argv: list[str]) -> tuple[list[str], list[str]]:
    """``[..., '--ros-args', ...]`` -> (our arguments, the ROS arguments from ``--ros-args`` on),
    so standard ROS arguments (remappings, ``__ns:=``, parameters) reach rclpy, not argparse."""
    if '--ros-args' not in argv:
        return argv, []
    start = argv.index('--ros-args')
    return argv[:start], argv[start:]


@contextlib.contextmanager
def stop_signals_interrupt():
    """SIGINT and SIGTERM raise KeyboardInterrupt in the main thread; yields the signals received."""
    received = []

    def interrupt(signum, _frame):
        received.append(signum)
        raise KeyboardInterrupt

    previous = {sig: signal.signal(sig, interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield received
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


if __name__ == '__main__':
    sys.exit(main())
