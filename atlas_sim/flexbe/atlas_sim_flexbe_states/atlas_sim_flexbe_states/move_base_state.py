"""MoveBaseState: the mobile manipulator's navigation, on the simulator."""

from flexbe_core import EventState, Logger

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class MoveBaseState(EventState):
    """
    Drives the mobile base to a waypoint (the simulator's navigate capability).

    ># waypoint     object   Where to go.

    <= arrived               The base reached the waypoint.
    <= failed                Navigation failed.
    <= blocked               The way is blocked.
    """

    def __init__(self):
        super().__init__(outcomes=['arrived', 'failed', 'blocked'], input_keys=['waypoint'])
        self._run = CapabilityRequest('navigate', type(self).__name__)

    def on_enter(self, userdata):
        Logger.loginfo(f'MoveBaseState: driving to {userdata.waypoint}')
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('arrived', 'failed')
