"""The server takes a burst of goal requests MAX_TAKEN at a time (ros/action_server.py):
rclpy's ActionServer takes one per executor pass, and 200 goals sent at once were accepted
over 5 s."""

import time

import pytest
from rclpy.action import ActionClient, ActionServer, GoalResponse
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from synthesis_manager.ros.action_server import MAX_TAKEN, BurstActionServer
from synthesis_manager.ros.env import init_ros
from synthesis_manager.ros.harness import reserve_domain_id
from synthesis_manager.ros.qos import action_client_qos, action_server_qos
from synthesis_msgs.action import BehaviorSynthesis

pytestmark = pytest.mark.ros

GOALS = 30


def goals_accepted_in_one_pass(server_class) -> int:
    """Send GOALS goals to a server whose executor has not run yet, let them all arrive, then
    run its executor for exactly one pass: how many goals it accepted in it."""
    import rclpy

    with reserve_domain_id() as domain:
        context = init_ros(args=[], domain_id=domain, context=rclpy.Context())
        try:
            server_node, client_node = Node('burst_server', context=context), Node('burst_client', context=context)
            admitted = []

            def admit(_goal):
                admitted.append(time.monotonic())
                return GoalResponse.ACCEPT

            server_class(server_node, BehaviorSynthesis, 'burst', execute_callback=lambda handle: handle.abort() or BehaviorSynthesis.Result(),
                         goal_callback=admit, **action_server_qos())  # the suite's deep queues
            client = ActionClient(client_node, BehaviorSynthesis, 'burst', **action_client_qos())
            assert client.wait_for_server(timeout_sec=10)
            for _ in range(GOALS):
                client.send_goal_async(BehaviorSynthesis.Goal())
            # Every request has arrived in the server's queue: nothing tells it without taking them,
            # which is what is measured, so the wait stays a fixed one.
            time.sleep(1.0)
            executor = SingleThreadedExecutor(context=context)
            executor.add_node(server_node)
            executor.spin_once(timeout_sec=5.0)
            taken = len(admitted)
            deadline = time.monotonic() + 3.0  # the rest, so that every goal's execution ends
            while time.monotonic() < deadline and (len(admitted) < GOALS or executor._tasks):
                executor.spin_once(timeout_sec=0.05)
            executor.shutdown()
            return taken
        finally:
            context.try_shutdown()


@pytest.mark.parametrize('server_class, accepted', [(BurstActionServer, MAX_TAKEN), (ActionServer, 1)])
def test_a_burst_of_goals_is_taken_in_one_executor_pass(server_class, accepted):
    assert goals_accepted_in_one_pass(server_class) == accepted
