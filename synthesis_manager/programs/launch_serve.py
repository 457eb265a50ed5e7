"""The suite under ``ros2 launch``: ``behavior_synthesis_bringup/launch/suite.launch.py`` starts
``behavior-synthesis serve`` with one launch argument per ``serve`` option.

The launch arguments are read from ``serve``'s own argument parser (``--config-dir`` becomes
``config_dir:=DIR``), so a new ``serve`` option is a launch argument without any change here.
An empty value (the default) leaves the option out: ``serve``'s own default applies. A
repeatable option (``--namespace``) takes a comma-separated list, a flag ``true``/``false``.
``ros_args`` passes standard ROS arguments (``ros_args:='-r __ns:=/robot1'``).

The launch file runs in the Python of the user's ``ros2`` (their ROS installation), which need
not have the suite: it runs ``python -m synthesis_manager.programs.launch_serve`` with the interpreter of
the ``behavior-synthesis`` it finds, first with ``--arguments`` (the launch arguments as JSON),
then with the values given (``name:=value`` items). That process is ``serve`` itself, except that
a stop asked by the launcher (SIGINT, SIGTERM) ends it with status 0: ``ros2 launch`` reports any
other status as "process has died", and under a launcher that stop is the normal end.
"""

from __future__ import annotations

import argparse
import json
import shlex
import signal
import sys
from dataclasses import dataclass

from respec.vocabulary.errors import ExitStatus

#: The launch argument that carries standard ROS arguments (``--ros-args ...``).
ROS_ARGS = 'ros_args'
ROS_ARGS_DESCRIPTION = "standard ROS arguments for the suite's nodes, e.g. '-r __ns:=/robot1'"
_STOPPED_BY_LAUNCHER = {128 + signal.SIGINT, 128 + signal.SIGTERM}


@dataclass(frozen=True)
class LaunchArgument:
    """One ``serve`` option as a launch argument."""

    name: str          # the launch argument, e.g. config_dir
    option: str        # serve's option, e.g. --config-dir
    kind: str          # 'value', 'list' (repeatable, comma-separated) or 'flag'
    description: str

    def argv(self, value: str) -> list[str]:
        """``serve``'s arguments for the launch argument's ``value`` ('' leaves the option out)."""
        value = value.strip()
        if not value:
            return []
        if self.kind == 'flag':
            if value.lower() not in ('true', 'false'):
                raise ValueError(f'launch argument {self.name}:={value!r}: use true or false')
            return [self.option] if value.lower() == 'true' else []
        if self.kind == 'list':
            return [word for item in value.split(',') if item.strip() for word in (self.option, item.strip())]
        return [self.option, value]


def serve_parser() -> argparse.ArgumentParser:
    """``behavior-synthesis serve``'s parser, as the command line builds it."""
    from synthesis_manager.programs.cli import build_parser

    # argparse lists a parser's options and their kinds only in private attributes and classes.
    subparsers = next(action for action in build_parser(only='serve')._actions  # noqa: SLF001
                      if isinstance(action, argparse._SubParsersAction))  # noqa: SLF001
    return subparsers.choices['serve']


def serve_launch_arguments() -> list[LaunchArgument]:
    """Every option of ``serve`` (but ``--help``) as a launch argument, in ``serve --help``'s order."""
    arguments = []
    for action in serve_parser()._actions:  # noqa: SLF001
        long_options = [option for option in action.option_strings if option.startswith('--')]
        if not long_options or isinstance(action, argparse._HelpAction):  # noqa: SLF001
            continue
        if isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction)):  # noqa: SLF001
            kind = 'flag'
        elif isinstance(action, argparse._AppendAction):  # noqa: SLF001
            kind = 'list'
        else:
            kind = 'value'
        option = long_options[0]
        described = (action.help or '') % {'default': action.default}
        more = '; comma-separated' if kind == 'list' else ''
        default = '' if action.default in (None, '', []) or 'default' in described else f' {action.default}'
        arguments.append(LaunchArgument(option[2:].replace('-', '_'), option, kind,
                                        f'serve {option}: {described}{more}; empty: serve\'s default{default}'))
    return arguments


def serve_argv(values: dict[str, str]) -> list[str]:
    """``serve``'s arguments for the launch arguments' ``values`` (name -> text)."""
    argv = [word for argument in serve_launch_arguments() for word in argument.argv(values.get(argument.name, ''))]
    ros_args = shlex.split(values.get(ROS_ARGS, ''))
    return argv + (['--ros-args', *ros_args] if ros_args else [])


def launch_values(items: list[str]) -> dict[str, str]:
    """``['config_dir:=DIR', ...]`` (what the launch file passes) -> {name: value}; ValueError names
    an item that is no ``name:=value`` of a launch argument."""
    known = {argument.name for argument in serve_launch_arguments()} | {ROS_ARGS}
    values = {}
    for item in items:
        name, separator, value = item.partition(':=')
        if not separator or name not in known:
            raise ValueError(f'{item!r} is no launch argument of the suite (known: {", ".join(sorted(known))})')
        values[name] = value
    return values


def main(argv: list[str] | None = None) -> int:
    """``--arguments``: the launch arguments as JSON (the launch file declares them); otherwise
    ``name:=value`` items: ``serve`` with them until the launcher stops it."""
    from synthesis_manager.programs.cli import main as cli_main

    argv = sys.argv[1:] if argv is None else argv
    if argv == ['--arguments']:
        described = [{'name': a.name, 'description': a.description} for a in serve_launch_arguments()]
        described.append({'name': ROS_ARGS, 'description': ROS_ARGS_DESCRIPTION})
        print(json.dumps(described))
        return 0
    try:
        serve = serve_argv(launch_values(argv))
    except ValueError as error:
        print(f'behavior synthesis launch: {error}', file=sys.stderr)
        return ExitStatus.USAGE
    status = cli_main(['serve', *serve])
    return 0 if status in _STOPPED_BY_LAUNCHER else status


if __name__ == '__main__':
    sys.exit(main())
