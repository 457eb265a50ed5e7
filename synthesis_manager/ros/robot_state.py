"""The robot's state as the server sees it: the latest synthesis_msgs/RobotState on a topic.

Synthesis on the fly needs the state the robot is in *now*: a message received before a
request may predate what the robot just finished, so :meth:`RobotStateListener.next_state`
waits for the first message received after it was called (robots publish periodically;
the simulator node at ``state_rate`` Hz).
"""

from __future__ import annotations

import threading
import time

from synthesis_manager.ros.stage_calls import WATCH_PERIOD, next_executor_turn
from synthesis_msgs.msg import RobotState


class RobotStateListener:
    """Subscribes ``node`` to ``topic`` and hands out fresh RobotState messages."""

    def __init__(self, node, topic: str, callback_group=None):
        self.topic = topic
        self._latest: RobotState | None = None
        self._received = 0
        self._changed = threading.Condition()
        self.subscription = node.create_subscription(RobotState, topic, self._on_state, 10,
                                                     callback_group=callback_group)

    def _on_state(self, message: RobotState) -> None:
        with self._changed:
            self._latest = message
            self._received += 1
            self._changed.notify_all()

    def next_state(self, timeout: float, should_stop=lambda: False) -> RobotState | None:
        """The first message received from now on; None after ``timeout`` s or once ``should_stop()``."""
        deadline = time.monotonic() + timeout
        with self._changed:
            seen = self._received
            while self._received == seen:
                remaining = deadline - time.monotonic()
                if remaining <= 0 or should_stop():
                    return None
                self._changed.wait(min(remaining, 0.02))
            return self._latest

    async def next_state_async(self, timeout: float, should_stop=lambda: False) -> RobotState | None:
        """:meth:`next_state` for coroutines (async execute callbacks): checks at each executor
        turn instead of blocking an executor thread."""
        deadline = time.monotonic() + timeout
        with self._changed:
            seen = self._received
        while True:
            with self._changed:
                if self._received != seen:
                    return self._latest
            if time.monotonic() > deadline or should_stop():
                return None
            await next_executor_turn(lambda: self._received != seen, WATCH_PERIOD)
