"""``behavior-synthesis serve``: the whole suite in one process until SIGINT/SIGTERM.

Standard ROS arguments after ``--ros-args`` apply to every node of the process (e.g.
``--ros-args -r __ns:=/robot1``); ``--namespace`` (repeatable) starts the nodes once per robot
namespace with one shared synthesis service (docs/deployment.md).
"""

from __future__ import annotations

import sys

from respec.vocabulary.errors import ExitStatus, exit_status_help
from respec.vocabulary.naming import parse_names
from synthesis_manager.ros.node_main import run_nodes
from synthesis_manager.suite import (SUITE_NODE_NAMES, add_namespace_arguments, add_suite_arguments,
                                     robot_namespaces, suite_node_factories)


def add_arguments(parser):
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.USAGE)
    add_suite_arguments(parser)
    parser.add_argument('--nodes', default=','.join(SUITE_NODE_NAMES),
                        help=f'comma-separated subset of: {", ".join(SUITE_NODE_NAMES)}')
    add_namespace_arguments(parser)


def run(args) -> int:
    names = parse_names(args.nodes)
    unknown = sorted(set(names) - set(SUITE_NODE_NAMES))
    if unknown:
        print(f'behavior-synthesis serve: unknown node {unknown[0]!r}', file=sys.stderr)
        return ExitStatus.USAGE
    namespaces = ', '.join(filter(None, robot_namespaces(args)))
    return run_nodes(*suite_node_factories(args, names),
                     argv=['behavior-synthesis', *getattr(args, 'ros_args', [])],
                     ready_message=f'behavior synthesis suite up: {", ".join(names)}'
                                   f'{" in " + namespaces if namespaces else ""} '
                                   '(actions behavior_synthesis and flexbe_synthesis); Ctrl-C to stop')
