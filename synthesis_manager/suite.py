"""The four nodes of the synthesis suite and their shared settings."""

from __future__ import annotations

import contextlib
import functools

from rclpy.node import Node
from rclpy.parameter import Parameter

from respec.errors import CodedError, ErrorCode
from respec.robot.files import add_config_dir_argument
from synthesis_manager.client import SynthesisClient
from synthesis_manager.nodes.ltl_compilation_node import LTLCompilationNode
from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode
from synthesis_manager.nodes.server_node import BehaviorSynthesisServer
from synthesis_manager.nodes.sm_generation_node import SMGenerationNode
from synthesis_manager.ros.harness import RosHarness

SUITE_NODE_NAMES = ('ltl_compilation', 'ltl_synthesis', 'sm_generation', 'behavior_synthesis_server')


def add_suite_arguments(parser):
    """Command-line settings shared by ``serve``, ``demo`` and ``execute``."""
    group = parser.add_argument_group('suite settings')
    add_config_dir_argument(group)
    group.add_argument('--byproducts-dir', default='', help='where the synthesizer writes its byproducts')
    group.add_argument('--keep-byproducts', type=int, default=None, metavar='N',
                       help="keep the newest N spec names' byproduct files (default 200; 0: none)")
    group.add_argument('--backend', choices=('builtin', 'slugs'), default='builtin',
                       help='synthesizer: our own (builtin) or a slugs executable on PATH')
    group.add_argument('--slugs-executable', default='slugs', help='the executable for --backend slugs')
    group.add_argument('--synthesis-timeout', type=float, default=120.0, help='seconds per synthesis')
    group.add_argument('--strategy-cache-mb', type=float, default=None, metavar='MB',
                       help='MiB of synthesis answers kept for identical requests, least recently used '
                            'dropped first (default 64; 0: no cache)')
    group.add_argument('--strategy-cache-dir', default='', metavar='DIR',
                       help='keep the strategy cache in this private directory too, so that a restarted '
                            'server finds it (default: memory only)')
    group.add_argument('--service-timeout', type=float, default=5.0,
                       help='seconds to wait for a pipeline service to appear')
    group.add_argument('--default-system', default='',
                       help='system for requests naming none or "system_wide" (default: atlas)')
    group.add_argument('--robot-state-topic', default='',
                       help='where requests naming no initial conditions (or "current") read them '
                            '(synthesis_msgs/RobotState; default: atlas_sim/state)')
    group.add_argument('--robot-state-timeout', type=float, default=None,
                       help='seconds to wait for a robot state (default: 2)')
    group.add_argument('--repair-time-budget', type=float, default=None, metavar='S',
                       help='seconds to search for verified fixes of a goal refused as impossible, '
                            'suggested in its result (default: 3; 0: none)')


def suite_node_factories(args=None, names=SUITE_NODE_NAMES):
    """Factories (taking ``context=``) for the suite's nodes, parametrised from ``args``."""
    def overrides(**values):
        return [Parameter(name, value=value) for name, value in values.items()
                if value not in ('', None)]

    settings = {
        'ltl_compilation': (LTLCompilationNode, overrides(config_dir=getattr(args, 'config_dir', ''))),
        'ltl_synthesis': (LTLSynthesisNode, overrides(
            byproducts_dir=getattr(args, 'byproducts_dir', ''),
            keep_byproducts=getattr(args, 'keep_byproducts', None),
            backend=getattr(args, 'backend', ''),
            slugs_executable=getattr(args, 'slugs_executable', ''),
            timeout=getattr(args, 'synthesis_timeout', None),
            strategy_cache_mb=getattr(args, 'strategy_cache_mb', None),
            strategy_cache_dir=getattr(args, 'strategy_cache_dir', ''))),
        'sm_generation': (SMGenerationNode, overrides(config_dir=getattr(args, 'config_dir', ''))),
        'behavior_synthesis_server': (BehaviorSynthesisServer, overrides(
            synthesis_timeout=getattr(args, 'synthesis_timeout', None),
            service_timeout=getattr(args, 'service_timeout', None),
            default_system=getattr(args, 'default_system', ''),
            config_dir=getattr(args, 'config_dir', ''),
            robot_state_topic=getattr(args, 'robot_state_topic', ''),
            robot_state_timeout=getattr(args, 'robot_state_timeout', None),
            repair_time_budget=getattr(args, 'repair_time_budget', None))),
    }
    return [functools.partial(settings[name][0], parameter_overrides=settings[name][1])
            for name in names]


class SuiteUnavailableError(CodedError):
    """The in-process suite's action server did not come up."""

    code = ErrorCode.SERVICE_UNAVAILABLE


@contextlib.contextmanager
def in_process_suite(args=None, client_name: str = 'suite_client'):
    """The four suite nodes plus a client node in this process, on a private ROS domain.

    Yields ``(harness, client)``; ``client`` is a SynthesisClient whose server is up.
    """
    with RosHarness() as ros:
        for factory in suite_node_factories(args):
            ros.add_node(factory)
        client = SynthesisClient(ros.add_node(Node, client_name))
        if not client.wait_for_server(timeout=10.0):
            raise SuiteUnavailableError('the /behavior_synthesis action server did not come up')
        yield ros, client
