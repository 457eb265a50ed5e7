"""Cancel at every stage, missing and hanging services: clear codes, never a hang."""

import threading
import time
from argparse import Namespace

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_msgs.srv import GenerateFlexBESM, GenerateLTLSpecification

from suite_in_process import make_slow_service, start_with_stand_ins as start

pytestmark = pytest.mark.ros

PAPER_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'pickup_object'])


def cancel_when(client, goal, status_prefix):
    """Run ``goal`` and cancel it as soon as feedback says ``status_prefix``."""
    cancel = threading.Event()

    def feedback(status, progress):
        if status.startswith(status_prefix):
            cancel.set()

    started = time.monotonic()
    outcome = client.run(goal, feedback=feedback, cancel=cancel, timeout=60)
    return outcome, time.monotonic() - started


@pytest.mark.parametrize('node, service_type, service, status', [
    ('ltl_compilation', GenerateLTLSpecification, 'ltl_compilation', 'Compiling'),
    ('sm_generation', GenerateFlexBESM, 'sm_generate', 'Generating'),
])
def test_cancel_while_a_stage_is_running(ros, tmp_path, node, service_type, service, status):
    client, _ = start(ros, tmp_path, replace={node: make_slow_service(service_type, service, 30)})
    outcome, seconds = cancel_when(client, make_goal(**PAPER_TASK), status)
    assert outcome.error_name == 'PREEMPTED'
    assert seconds < 10


def test_missing_service_gives_service_unavailable(ros, tmp_path):
    client, _ = start(ros, tmp_path, replace={'ltl_compilation': None})
    outcome = client.run(make_goal(**PAPER_TASK), timeout=30)
    assert outcome.error_name == 'SERVICE_UNAVAILABLE'
    assert 'ltl_compilation' in outcome.message


def test_hanging_service_times_out(ros, tmp_path):
    client, stand_ins = start(
        ros, tmp_path,
        replace={'sm_generation': make_slow_service(GenerateFlexBESM, 'sm_generate', 60)},
        server_parameters=[Parameter('generation_timeout', value=1.0)])
    outcome = client.run(make_goal(**PAPER_TASK), timeout=30)
    stand_ins[0].release.set()
    assert outcome.error_name == 'TIMEOUT'
    assert 'sm_generate' in outcome.message


# A synthesis that never ends by itself: 40 sensors that nothing constrains give 2**40 initial
# states to the strategy (solving is quick, extraction is not), so a cancel or a time limit is
# always what ends it.
LONG_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down'],
                 ltl_specification={'env_props': [f'sensor{i}' for i in range(40)]})


def test_cancel_in_the_middle_of_synthesis_really_stops_it(ros, tmp_path):
    client, _ = start(ros, tmp_path)
    synthesis_node = next(n for n in ros.nodes if n.get_name() == 'ltl_synthesis')
    outcome, seconds = cancel_when(client, make_goal(**LONG_TASK), 'Synthesizing')
    assert outcome.error_name == 'PREEMPTED'
    # The synthesizer forgets a request only when its work has returned: it really stopped.
    deadline = time.monotonic() + 5
    while synthesis_node.active_requests() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert synthesis_node.active_requests() == []
    assert seconds < 10
    # ...and the server keeps serving.
    assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'


def test_synthesis_time_limit_gives_synthesis_timeout_and_the_server_keeps_serving(ros, tmp_path):
    client, _ = start(ros, tmp_path)
    started = time.monotonic()
    outcome = client.run(make_goal(**LONG_TASK, timeout=2.5), timeout=60)
    assert outcome.error_name == 'SYNTHESIS_TIMEOUT'
    assert '2.5 s' in outcome.message  # the goal's limit: it counts compilation and waiting too
    assert time.monotonic() - started < 2.5 + 1 + 1  # the answer within a second of it (+ client overhead)
    assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'


def test_slugs_backend_calls_an_external_slugs_compatible_executable(ros, tmp_path):
    """The 'slugs' backend, exercised with our own gr1synth as the executable (slugs is not here)."""
    import sys
    from pathlib import Path

    from synthesis_manager.suite import suite_node_factories
    from synthesis_manager.nodes.server_node import BehaviorSynthesisServer

    gr1synth = str(Path(sys.executable).parent / 'gr1synth')
    args = Namespace(config_dir='', byproducts_dir=str(tmp_path), backend='slugs',
                     slugs_executable=gr1synth, synthesis_timeout=60.0, service_timeout=1.0)
    for factory in suite_node_factories(args, ['ltl_compilation', 'ltl_synthesis', 'sm_generation']):
        ros.add_node(factory)
    ros.add_node(BehaviorSynthesisServer)
    client = SynthesisClient(ros.add_node(Node, 'slugs_client'))
    assert client.wait_for_server(timeout=10.0)
    outcome = client.run(make_goal(**PAPER_TASK, name='external'), timeout=60)
    assert outcome.error_name == 'SUCCESS', outcome.message
    assert outcome.states
    assert (tmp_path / 'external.json').read_text().startswith('{')

    missing = Namespace(**{**vars(args), 'slugs_executable': str(tmp_path / 'no-such-slugs')})
    ros.add_node(suite_node_factories(missing, ['ltl_synthesis'])[0], namespace='broken')
    broken = ros.nodes[-1]
    from synthesis_msgs.srv import SynthesizeAutomaton
    from synthesis_manager.ros.conversions import sections_to_msg
    from synthesis_manager.ros.harness import wait_for

    caller = ros.add_node(Node, 'direct_caller')
    service = caller.create_client(SynthesizeAutomaton, '/broken/ltl_synthesis')
    assert service.wait_for_service(timeout_sec=10.0)
    response = wait_for(service.call_async(SynthesizeAutomaton.Request(
        ltl_specification=sections_to_msg(outcome.ltl_specification), spec_name='x')))
    assert broken.get_namespace() == '/broken'
    assert response.error_code.value == response.error_code.SYNTHESIZER_BACKEND_FAILED
    assert 'no-such-slugs' in response.error_code.message
