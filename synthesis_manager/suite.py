"""The four nodes of the synthesis suite and their shared settings."""

from __future__ import annotations

import contextlib
import functools

from rclpy.node import Node
from rclpy.parameter import Parameter

from respec.vocabulary.errors import CodedError, ErrorCode
from synthesis_manager.client import SynthesisClient
from synthesis_manager.nodes.ltl_compilation_node import LTLCompilationNode
from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode
from synthesis_manager.nodes.server_node import BehaviorSynthesisServer
from synthesis_manager.nodes.sm_generation_node import SMGenerationNode
from synthesis_manager.ros.harness import RosHarness
from synthesis_manager.ros.namespaces import absolute_namespace, namespace_placement, synthesis_service_remapping
from synthesis_manager.settings import add_suite_flags, node_overrides

SUITE_NODE_NAMES = ('ltl_compilation', 'ltl_synthesis', 'sm_generation', 'behavior_synthesis_server')


def add_suite_arguments(parser):
    """Command-line settings shared by ``serve``, ``demo``, ``execute``, ``export-behavior`` and
    ``gui`` (synthesis_manager.settings.SUITE_FLAGS)."""
    add_suite_flags(parser)


def suite_node_factories(args=None, names=SUITE_NODE_NAMES):
    """Factories (taking ``context=``) for the suite's nodes, parametrised from ``args``."""
    node_classes = {'ltl_compilation': LTLCompilationNode, 'ltl_synthesis': LTLSynthesisNode,
                    'sm_generation': SMGenerationNode, 'behavior_synthesis_server': BehaviorSynthesisServer}
    namespaces = robot_namespaces(args)
    synthesis_namespace = shared_synthesis_namespace(args)
    factories = []
    for name in names:
        parameters = [Parameter(setting, value=value) for setting, value in node_overrides(args, name).items()]
        for namespace in ([synthesis_namespace] if name == 'ltl_synthesis' else namespaces):
            placement = namespace_placement(namespace)
            if name == 'behavior_synthesis_server' and synthesis_namespace != namespace:
                placement['cli_args'] = synthesis_service_remapping(synthesis_namespace)
            factories.append(functools.partial(node_classes[name], parameter_overrides=parameters, **placement))
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
