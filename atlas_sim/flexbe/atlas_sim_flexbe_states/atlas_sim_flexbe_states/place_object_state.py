"""PlaceObjectState: the mobile manipulator's placing, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class PlaceObjectState(EventState):
    """
    Places the held object on a surface (the simulator's place capability).

    -- surface      string   Where to place it, e.g. "table".

    <= placed                The object was placed.
    <= failed                Placing failed.
    """

    def __init__(self, surface):
        super().__init__(outcomes=['placed', 'failed'])
        self._run = CapabilityRequest('place', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('placed', 'failed')
