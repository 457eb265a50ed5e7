"""Servers keep a response until the client's response reader is matched (ros/fastdds_loopback.xml).

rmw_fastrtps drops a service response when the client's response reader is not matched within
the response writer's max_blocking_time. A client that cannot recover from that, such as the
FlexBE WebUI's action client, then waits forever. The suite's profile makes that wait 5 s.
"""

import time
import warnings

import pytest
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from synthesis_manager.ros.harness import RosHarness
from waiting import wait_until

pytestmark = pytest.mark.ros

RESPONSE_WAIT_S = 5.0  # the profile's max_blocking_time for service response writers


def _answer_one_request(client_qos: QoSProfile) -> tuple[float, bool, list[str]]:
    """A server sends one response by hand; returns how long sending took, whether the client got
    it, and the warnings rclpy gave."""
    from rcl_interfaces.srv import ListParameters

    with RosHarness() as ros:
        server_node = Node('response_wait_server', context=ros.context)  # not spun: answered by hand
        service = server_node.create_service(ListParameters, 'response_wait', lambda request, response: response)
        client = ros.add_node(Node, 'response_wait_client').create_client(
            ListParameters, 'response_wait', qos_profile=client_qos)
        if client_qos.durability == DurabilityPolicy.VOLATILE:
            assert client.wait_for_service(timeout_sec=30.0)
        # else wait_for_service would wait for the response reader too; the request itself is
        # TRANSIENT_LOCAL, so the server gets it whenever its request reader matches.
        answered = client.call_async(ListParameters.Request())
        taken = []

        def request_taken() -> bool:
            request, header = service.handle.service_take_request(ListParameters.Request) or (None, None)
            if request is not None:
                taken.append(header)
            return bool(taken)

        wait_until(request_taken, 30.0, 'the server took the request')
        with warnings.catch_warnings(record=True) as given:
            warnings.simplefilter('always')
            started = time.monotonic()
            service.send_response(ListParameters.Response(), taken[0])
            sending_s = time.monotonic() - started
        if client_qos.durability == DurabilityPolicy.VOLATILE:
            wait_until(answered.done, 30.0, 'the client got its response')
        server_node.destroy_node()
        return sending_s, answered.done(), [str(warning.message) for warning in given]


def test_a_response_waits_for_the_clients_reader_before_it_is_dropped():
    # A response reader asking for TRANSIENT_LOCAL never matches the server's VOLATILE writer:
    # it stands for a reader that discovery has not matched yet. Fast DDS's default gives up
    # after 0.1 s.
    never_matched = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                               durability=DurabilityPolicy.TRANSIENT_LOCAL)
    sending_s, delivered, given = _answer_one_request(never_matched)
    assert sending_s >= RESPONSE_WAIT_S - 0.5, f'the response was dropped after {sending_s:.2f} s'
    assert not delivered
    assert any('client will not receive response' in message for message in given), given


def test_a_matched_client_gets_its_response_without_that_wait():
    matched = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
    sending_s, delivered, given = _answer_one_request(matched)
    assert delivered and given == []
    assert sending_s < RESPONSE_WAIT_S - 0.5, f'sending took {sending_s:.2f} s'
