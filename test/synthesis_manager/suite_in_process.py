"""The ROS suite in this process (a RosHarness): with its synthesis node's parameters set, or
with some stages replaced by stand-ins that answer slowly; each returns a client."""

import threading
from argparse import Namespace

from rclpy.node import Node
from rclpy.parameter import Parameter

from suite_settings import suite_args
from synthesis_manager.client import SynthesisClient
from synthesis_manager.nodes.server_node import BehaviorSynthesisServer
from synthesis_manager.suite import suite_node_factories

PAPER_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'pickup_object'])


def reliability_suite_args(byproducts_dir, **overrides):
    return suite_args(byproducts_dir, **{'service_timeout': 5.0, **overrides})


def start_suite(ros, tmp_path, names=('ltl_compilation', 'ltl_synthesis', 'sm_generation'),
                server_parameters=(), synthesis_parameters=()):
    """The suite in ``ros`` (the synthesis node with extra parameters); returns a client."""
    from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode

    for factory in suite_node_factories(reliability_suite_args(tmp_path), [n for n in names if n != 'ltl_synthesis']):
        ros.add_node(factory)
    if 'ltl_synthesis' in names:
        ros.add_node(LTLSynthesisNode, parameter_overrides=[
            Parameter('byproducts_dir', value=str(tmp_path)), *synthesis_parameters])
    ros.add_node(BehaviorSynthesisServer, parameter_overrides=list(server_parameters))
    client = SynthesisClient(ros.add_node(Node, 'reliability_client'))
    assert client.wait_for_server(timeout=10.0)
    return client


def make_slow_service(service_type, name, seconds):
    """A stand-in pipeline service that takes ``seconds`` to answer (or forever)."""
    def factory(context, **kwargs):
        from rclpy.callback_groups import ReentrantCallbackGroup

        node = Node(f'slow_{name}', context=context)
        release = threading.Event()
        node.release = release
        node.stop_work = release.set  # the harness ends running callbacks before teardown

        def handle(request, response):
            release.wait(seconds)
            response.error_code.value = response.error_code.FAILURE
            response.error_code.message = 'slow stand-in answered'
            return response

        node.create_service(service_type, name, handle, callback_group=ReentrantCallbackGroup())
        return node
    return factory


def start_with_stand_ins(ros, tmp_path, replace=None, server_parameters=()):
    """The suite with some services replaced by stand-ins; returns a client."""
    names = ['ltl_compilation', 'ltl_synthesis', 'sm_generation']
    args = Namespace(config_dir='', byproducts_dir=str(tmp_path), backend='builtin',
                     slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=1.0)
    replace = replace or {}
    real = [n for n in names if n not in replace and n is not None]
    for factory in suite_node_factories(args, real):
        ros.add_node(factory)
    stand_ins = [ros.add_node(factory) for factory in replace.values() if factory is not None]
    ros.add_node(BehaviorSynthesisServer, parameter_overrides=[
        Parameter('service_timeout', value=1.0), *server_parameters])
    client = SynthesisClient(ros.add_node(Node, 'cancel_client'))
    assert client.wait_for_server(timeout=10.0)
    return client, stand_ins
