"""A stage whose node is replaced while it works (a restarted host): the new node offers the
service again before the old one's lease ends, so the service never looks unavailable, yet the
pending request went to the old one and will never be answered. Measured across hosts
(test_fleet_hosts.py): a goal then waited for its 30 s generation limit (TIMEOUT); now it ends
SERVICE_UNAVAILABLE within about a second, and the next goal succeeds on the new node."""

import time

import pytest
from rclpy.parameter import Parameter

from synthesis_manager.client import make_goal
from synthesis_manager.nodes.sm_generation_node import SMGenerationNode
from synthesis_msgs.srv import GenerateFlexBESM
from suite_in_process import PAPER_TASK, make_slow_service, start_with_stand_ins as start

pytestmark = pytest.mark.ros


def test_a_request_to_a_node_that_was_replaced_ends_service_unavailable_at_once(ros, tmp_path):
    client, (old,) = start(ros, tmp_path,
                           replace={'sm_generation': make_slow_service(GenerateFlexBESM, 'sm_generate', 60)},
                           server_parameters=[Parameter('generation_timeout', value=30.0)])
    statuses = []
    result = {}

    def on_feedback(status, _):
        statuses.append(status)
        if status.startswith('Generating') and 'replaced' not in result:
            result['replaced'] = time.monotonic()
            ros.add_node(SMGenerationNode)  # the new node first: the service stays offered
            ros.executor.remove_node(old)
            old.destroy_node()

    outcome = client.run(make_goal(**PAPER_TASK), feedback=on_feedback, timeout=60)
    old.release.set()
    noticed = time.monotonic() - result['replaced']
    print(f'{outcome.error_name} {noticed:.2f} s after the node was replaced')
    assert outcome.error_name == 'SERVICE_UNAVAILABLE', outcome.message
    assert "went away before answering" in outcome.message and 'sm_generate' in outcome.message
    assert noticed < 5.0
    assert client.run(make_goal(**PAPER_TASK), timeout=60).succeeded  # the new node serves
