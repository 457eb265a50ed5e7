"""An rclpy ActionClient whose requests can no longer lose their responses (rclpy#1123).

rclpy 7.1 (Jazzy) sends a goal, cancel or result request first and registers its sequence
number afterwards. When the executor thread takes the response in between, it finds no
registration, logs "Ignoring unexpected goal response" and drops it: the caller's future
never completes (3 of ~800 sequential goals here). This subclass makes sending and
registering one step under a lock that the response handling waits for.

A goal response can also be lost on the way: rmw_fastrtps gives the server the response
writer's max_blocking_time (Fast DDS: 100 ms; the suite's profile: 5 s) to match the client's
response reader, and on a loaded machine discovery can take longer, so the server accepts and
runs the goal while its client waits for an answer that never comes (a send-goal waited 120 s
so). The server's status topic lists every accepted goal, so a goal
seen there is accepted whatever became of its response (``accepted_without_response``).
"""

from __future__ import annotations

import threading
from uuid import uuid4

from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from unique_identifier_msgs.msg import UUID

from synthesis_manager.ros.qos import action_client_qos


# A goal the server's status lists as accepted this long after it was sent, with no goal
# response yet, lost its response on the way: its caller goes on without it.
GOAL_RESPONSE_GRACE = 2.0


def new_goal_id() -> UUID:
    """A random goal id, as rclpy makes one, but known to the caller before sending."""
    return UUID(uuid=list(uuid4().bytes))


class RaceFreeActionClient(ActionClient):
    """ActionClient with the suite's deep queues and registration before any response."""

    def __init__(self, node, action_type, action_name, **kwargs):
        super().__init__(node, action_type, action_name, **{**action_client_qos(), **kwargs})
        self._registering = threading.Lock()
        # Goals whose response is awaited (goal id -> its acceptance stamp once the status
        # lists it), and the sequence numbers of goals accepted without their response.
        self._awaited: dict[bytes, object | None] = {}
        self._answered_by_status: set[int] = set()

    def send_goal_async(self, goal, feedback_callback=None, goal_uuid=None):
        goal_uuid = goal_uuid or new_goal_id()
        with self._registering:
            self._awaited[bytes(goal_uuid.uuid)] = None
            return super().send_goal_async(goal, feedback_callback, goal_uuid)

    def accepted_without_response(self, sent) -> bool:
        """Whether the server's status lists the goal of the request ``sent`` (a future of
        ``send_goal_async``) although its goal response has not come: then ``sent`` gets an
        accepted handle now (status updates keep going to the handle rclpy makes if the
        response still comes)."""
        with self._registering:
            # The executor removes answered requests without this lock: copies, and a done future is left alone.
            sequence = next((number for number, pending in list(self._pending_goal_requests.items())
                             if pending is sent), None)
            goal_id = self._goal_sequence_number_to_goal_id.get(sequence)
            stamp = self._awaited.get(bytes(goal_id.uuid)) if goal_id is not None else None
            if stamp is None or sequence is None or goal_id is None or sent.done():
                return False
            self._remove_pending_goal_request(sent)
            self._answered_by_status.add(sequence)
            del self._awaited[bytes(goal_id.uuid)]
        # Rare (a server without the suite's DDS profile, or discovery slower than its 5 s):
        # said so that a slow goal can be told from a slow server.
        self._node.get_logger().warning(
            f'no goal response from {self._node.resolve_service_name(self._action_name)}; its status '
            'lists the goal as accepted, so it goes on')
        # Outside the lock: a done callback may send the result request, which takes it.
        response = self._action_type.Impl.SendGoalService.Response(accepted=True, stamp=stamp)
        sent.set_result(ClientGoalHandle(self, goal_id, response))
        return True

    def stop_awaiting(self, goal_id) -> None:
        """The caller gave up on the goal's response: stop looking for it in the status (an
        answered goal is no longer looked for anyway)."""
        with self._registering:
            self._awaited.pop(bytes(goal_id.uuid), None)

    def _cancel_goal_async(self, goal_handle):
        with self._registering:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle):
        with self._registering:
            return super()._get_result_async(goal_handle)

    async def execute(self, taken_data):
        # A request being sent right now is registered before its response is looked up.
        with self._registering:
            if self._awaited and 'status' in taken_data:
                for status in taken_data['status'].status_list:
                    goal = bytes(status.goal_info.goal_id.uuid)
                    if goal in self._awaited:
                        self._awaited[goal] = status.goal_info.stamp
            if 'goal' in taken_data:
                sequence = taken_data['goal'][0]
                if sequence in self._answered_by_status:
                    # The late response of a goal answered from the status: not "unexpected".
                    self._answered_by_status.discard(sequence)
                    del taken_data['goal']
                elif (answered := self._goal_sequence_number_to_goal_id.get(sequence)) is not None:
                    self._awaited.pop(bytes(answered.uuid), None)
        await super().execute(taken_data)
