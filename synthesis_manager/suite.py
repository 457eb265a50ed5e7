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
from synthesis_manager.ros.namespaces import absolute_namespace, namespace_placement, synthesis_service_remapping

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
    group.add_argument('--strategy-cache-key-file', default='', metavar='FILE',
                       help="the 0600 key that signs the cache directory's entries (default: DIR.key "
                            'beside it, made on first use; give a fleet the same file)')
    group.add_argument('--memory-sum-limit-mb', type=float, default=None, metavar='MB',
                       help='MiB that the suite and all its synthesis, compilation and repair processes may hold together; '
                            'beyond it the working one holding the most is ended (default 4096; 0: none)')
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
            strategy_cache_dir=getattr(args, 'strategy_cache_dir', ''),
            strategy_cache_key_file=getattr(args, 'strategy_cache_key_file', ''),
            memory_sum_limit_mb=getattr(args, 'memory_sum_limit_mb', None))),
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
    namespaces = robot_namespaces(args)
    synthesis_namespace = shared_synthesis_namespace(args)
    factories = []
    for name in names:
        node_class, parameters = settings[name]
        for namespace in ([synthesis_namespace] if name == 'ltl_synthesis' else namespaces):
            placement = namespace_placement(namespace)
            if name == 'behavior_synthesis_server' and synthesis_namespace != namespace:
                placement['cli_args'] = synthesis_service_remapping(synthesis_namespace)
            factories.append(functools.partial(node_class, parameter_overrides=parameters, **placement))
    return factories


def add_namespace_arguments(parser):
    """``serve``'s robot namespaces: several robots' nodes side by side in one process."""
    group = parser.add_argument_group('robots side by side (docs/deployment.md)')
    group.add_argument('--namespace', action='append', default=[], metavar='NS', dest='namespaces',
                       help="a robot's ROS namespace, e.g. /robot1 (repeatable: the nodes of --nodes run "
                            'once per namespace, except ltl_synthesis, which runs once, in --synthesis-namespace)')
    group.add_argument('--synthesis-namespace', default=None, metavar='NS',
                       help='where the ltl_synthesis service the servers call lives (default: the one '
                            '--namespace given, or / for several): one synthesis service for several robots')


def robot_namespaces(args) -> list[str]:
    """The robots' namespaces of ``args`` ('' : the node's own, i.e. / or a ``__ns`` remapping)."""
    return [absolute_namespace(namespace) for namespace in getattr(args, 'namespaces', None) or ['']]


def shared_synthesis_namespace(args) -> str:
    """The namespace of the one ltl_synthesis service the servers of ``args`` call."""
    given = getattr(args, 'synthesis_namespace', None)
    if given is not None:
        return absolute_namespace(given) or '/'
    namespaces = robot_namespaces(args)
    return namespaces[0] if len(namespaces) == 1 else '/'


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
