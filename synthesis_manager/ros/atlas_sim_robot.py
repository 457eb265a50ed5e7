"""The executive's :class:`~atlas_sim.executive.robot.Robot` protocol over ROS: drives ``atlas_sim``.

One ``atlas_sim/execute`` goal (synthesis_msgs/action/ExecuteCapability) per activated
capability, the robot state from ``atlas_sim/state`` (synthesis_msgs/msg/RobotState).
The given node must be spinning in some executor (e.g. ``RosHarness.add_node``); the
executive calls this adapter from its own thread. RobotState carries no sensor readings,
so snapshots report none.

    with RosHarness() as ros:
        ros.add_node(AtlasSimNode)
        robot = RosRobot(ros.add_node(Node, 'executive'))
        robot.wait_until_ready()
        run = execute_state_machine(states, robot, robot_system('atlas'))
"""

from __future__ import annotations

import threading
import time
from typing import Any

from atlas_sim.executive.robot import CapabilityResult
from respec.vocabulary.errors import CodedError, ErrorCode
from synthesis_manager.nodes.atlas_sim_node import ACTION_NAME, STATE_TOPIC
from synthesis_manager.ros.action_client import GOAL_RESPONSE_GRACE, RaceFreeActionClient
from synthesis_msgs.action import ExecuteCapability
from synthesis_msgs.msg import RobotState


class RobotUnavailableError(CodedError):
    """The atlas_sim node does not answer."""

    code = ErrorCode.SERVICE_UNAVAILABLE


class _Goal:
    """A capability goal on its way: accepted, then its result."""

    def __init__(self, capability: str):
        self.capability = capability
        self.result: CapabilityResult | None = None


class RosRobot:
    """Robot protocol over the simulator node's action server and state topic."""

    def __init__(self, node, action_name: str = ACTION_NAME, state_topic: str = STATE_TOPIC,
                 poll_period: float = 0.002):
        self.node = node
        self.poll_period = poll_period
        self.client = RaceFreeActionClient(node, ExecuteCapability, action_name)
        self._unanswered: list[tuple[Any, float]] = []  # goal requests' futures and when they were sent
        self._state: RobotState | None = None
        self._latest_result_time = 0.0  # results may arrive before the next state message
        self._changed = threading.Condition()
        self.subscription = node.create_subscription(RobotState, state_topic, self._on_state, 10)

    def wait_until_ready(self, timeout: float = 10.0) -> None:
        """Wait for the action server and a first state message."""
        if not self.client.wait_for_server(timeout_sec=timeout):
            raise RobotUnavailableError(f'no {ACTION_NAME} action server', item=ACTION_NAME)
        deadline = time.monotonic() + timeout
        with self._changed:
            while self._state is None:
                if not self._changed.wait(max(0.0, deadline - time.monotonic())):
                    raise RobotUnavailableError(f'no message on {STATE_TOPIC}', item=STATE_TOPIC)

    def _on_state(self, message: RobotState) -> None:
        with self._changed:
            self._state = message
            self._changed.notify_all()

    # --- Robot protocol ------------------------------------------------------------------------------

    def start_concurrently(self, capabilities):
        # Sent back to back: the node starts goals arriving within its batch window together.
        goals = [_Goal(c) for c in capabilities]
        for goal in goals:
            future = self.client.send_goal_async(ExecuteCapability.Goal(capability=goal.capability))
            with self._changed:
                self._unanswered.append((future, time.monotonic()))
            future.add_done_callback(lambda f, goal=goal: self._on_goal_response(goal, f))
        return goals

    def _on_goal_response(self, goal: _Goal, future) -> None:
        handle = future.result()
        if not handle.accepted:
            self._finish(goal, 'failed', 'the simulator node rejected the goal', self.time())
            return
        handle.get_result_async().add_done_callback(lambda f: self._on_result(goal, f))

    def _on_result(self, goal: _Goal, future) -> None:
        result = future.result().result
        self._finish(goal, result.outcome or 'failed', result.reason, result.stamp)

    def _finish(self, goal: _Goal, outcome: str, reason: str, stamp: float) -> None:
        with self._changed:
            goal.result = CapabilityResult(goal.capability, outcome, reason, float(stamp))
            self._latest_result_time = max(self._latest_result_time, float(stamp))
            self._changed.notify_all()

    def step(self) -> None:
        """Wait briefly for news (a result or a state message); a goal whose response was lost
        on the way goes on once the node's status lists it (ros/action_client.py)."""
        with self._changed:
            self._changed.wait(self.poll_period)
            self._unanswered = [(sent, when) for sent, when in self._unanswered if not sent.done()]
            overdue = [sent for sent, when in self._unanswered if time.monotonic() - when > GOAL_RESPONSE_GRACE]
        for sent in overdue:
            self.client.accepted_without_response(sent)

    def result(self, handle: _Goal) -> CapabilityResult | None:
        return handle.result

    def time(self) -> float:
        """The robot clock: the latest stamp seen (state message or result)."""
        return max(self._state.stamp if self._state is not None else 0.0, self._latest_result_time)

    def snapshot(self) -> dict:
        state = self._state
        if state is None:
            raise RobotUnavailableError(f'no message on {STATE_TOPIC} yet', item=STATE_TOPIC)
        return {'time': self.time(), 'mode': state.mode, 'pending_mode': state.pending_mode or None,
                'completed_actions': list(state.completed_actions), 'running': list(state.running),
                'head_tilt': state.head_tilt, 'base_xy': list(state.base_xy),
                'pelvis_height': state.pelvis_height, 'holding_object': state.holding_object,
                'fallen': state.fallen, 'sensors': {}}
