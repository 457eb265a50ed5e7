"""An rclpy ActionClient whose requests can no longer lose their responses (rclpy#1123).

rclpy 7.1 (Jazzy) sends a goal, cancel or result request first and registers its sequence
number afterwards. When the executor thread takes the response in between, it finds no
registration, logs "Ignoring unexpected goal response" and drops it: the caller's future
never completes (3 of ~800 sequential goals here). This subclass makes sending and
registering one step under a lock that the response handling waits for.
"""

from __future__ import annotations

import threading

from rclpy.action import ActionClient

from synthesis_manager.ros.qos import action_client_qos


class RaceFreeActionClient(ActionClient):
    """ActionClient with the suite's deep queues and registration before any response."""

    def __init__(self, node, action_type, action_name, **kwargs):
        super().__init__(node, action_type, action_name, **{**action_client_qos(), **kwargs})
        self._registering = threading.Lock()

    def send_goal_async(self, goal, feedback_callback=None, goal_uuid=None):
        with self._registering:
            return super().send_goal_async(goal, feedback_callback, goal_uuid)

    def _cancel_goal_async(self, goal_handle):
        with self._registering:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle):
        with self._registering:
            return super()._get_result_async(goal_handle)

    async def execute(self, taken_data):
        # A request being sent right now is registered before its response is looked up.
        with self._registering:
            pass
        await super().execute(taken_data)
