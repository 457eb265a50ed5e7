"""A client of the atlas_sim node: sends capability goals and collects its RobotState messages."""

import threading
import time

from rclpy.node import Node

from synthesis_manager.nodes.atlas_sim_node import ACTION_NAME, STATE_TOPIC
from synthesis_manager.ros.action_client import GOAL_RESPONSE_GRACE, RaceFreeActionClient
from synthesis_manager.ros.harness import wait_for
from synthesis_msgs.action import ExecuteCapability
from synthesis_msgs.msg import RobotState


class Client:
    """Sends capability goals and collects RobotState messages."""

    def __init__(self, ros, name='sim_client'):
        self.node = ros.add_node(Node, name)
        # The product's client: rclpy's own can lose a goal's response (rclpy#1123).
        self.action = RaceFreeActionClient(self.node, ExecuteCapability, ACTION_NAME)
        assert self.action.wait_for_server(timeout_sec=10.0)
        self.states = []
        self.received = threading.Event()
        self.node.create_subscription(RobotState, STATE_TOPIC, self._on_state, 10)

    def _on_state(self, message):
        self.states.append(message)
        self.received.set()

    def wait_for_state(self, condition, timeout=5.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            found = [m for m in list(self.states) if condition(m)]
            if found:
                return found[0]
            time.sleep(0.01)
        raise AssertionError('no matching RobotState message')

    def send(self, capability):
        return self.action.send_goal_async(ExecuteCapability.Goal(capability=capability))

    def results(self, futures, timeout=60.0):
        handles = [self.accepted(f) for f in futures]
        return [wait_for(h.get_result_async(), timeout).result if h.accepted else None for h in handles]

    def accepted(self, sent, timeout=10.0):
        """The goal handle of the request ``sent``; a response lost on the way is made up from
        the node's status, as the product's clients do (ros/action_client.py)."""
        deadline, grace = time.monotonic() + timeout, time.monotonic() + GOAL_RESPONSE_GRACE
        while not sent.done() and time.monotonic() < deadline:
            if time.monotonic() > grace:
                self.action.accepted_without_response(sent)
            time.sleep(0.02)
        return wait_for(sent, 0.1)

    def execute(self, *capabilities):
        return self.results([self.send(c) for c in capabilities])
