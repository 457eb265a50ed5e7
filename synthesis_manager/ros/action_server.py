"""An rclpy ActionServer that takes every waiting request when it wakes, not one.

rclpy 7.1 (Jazzy) takes one goal request (and one cancel and one result request) each time the
executor finds an action server ready, and the executor builds its whole wait set again before
the next take. When 200 goals arrive at once, accepting them took 200 executor passes, each
behind the work of the goals already running: the last goals were accepted seconds after they
were sent, and their clients saw their time limits answered that much late. This subclass takes
what is waiting of each kind, up to MAX_TAKEN, in one pass and handles it in order.

Not more: a client with rclpy's default queues (the ros2 CLI, FlexBE WebUI, a plain
ActionClient) keeps only the last 10 responses it has not taken yet, and takes one per pass of
its own executor; a server answering a whole burst at once would overwrite some of them.
"""

from __future__ import annotations

from rclpy.action import ActionServer

MAX_TAKEN = 8  # requests of each kind taken in one pass


class BurstActionServer(ActionServer):
    """ActionServer taking every waiting goal, cancel and result request in one executor pass."""

    def take_data(self):
        data = super().take_data()
        impl = self._action_type.Impl
        for kind, take, request_type in (('goal', self._handle.take_goal_request, impl.SendGoalService.Request),
                                         ('cancel', self._handle.take_cancel_request, impl.CancelGoalService.Request),
                                         ('result', self._handle.take_result_request, impl.GetResultService.Request)):
            if kind not in data:
                continue
            more = []
            while len(more) < MAX_TAKEN - 1:  # one taken by rclpy's own take_data
                with self._lock:
                    taken = take(request_type)
                if not all(taken):  # nothing more waiting: rclpy's (None, None)
                    break
                more.append(taken)
            data[f'more {kind}'] = more
        return data

    async def execute(self, taken_data):
        await super().execute(taken_data)
        for request in taken_data.get('more goal', ()):
            await self._execute_goal_request(request)
        for request in taken_data.get('more cancel', ()):
            await self._execute_cancel_request(request)
        for request in taken_data.get('more result', ()):
            await self._execute_get_result_request(request)
