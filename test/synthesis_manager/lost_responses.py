"""An action client that loses every goal response, as a loaded machine can (ros/action_client.py)."""

from synthesis_manager.ros.action_client import RaceFreeActionClient


class GoalResponseLosingClient(RaceFreeActionClient):
    """Its goal responses are all lost on the way, as when rmw_fastrtps's server gives up on
    matching a client's response reader (100 ms) on a loaded machine."""

    lost = 0

    async def execute(self, taken_data):
        if taken_data.pop('goal', None) is not None:
            self.lost += 1
        await super().execute(taken_data)
