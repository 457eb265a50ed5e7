"""SetBaseModeState: the mobile manipulator's base/arm control mode, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class SetBaseModeState(EventState):
    """
    Switches the mobile manipulator's control mode (the simulator capability of that name).

    -- mode         string   A class constant or its value (SetBaseModeState.PARKED or "parked").

    <= changed               The robot is in the mode.
    <= failed                The mode change failed.
    """

    PARKED = 'parked'
    DRIVING = 'driving'
    MANIPULATING = 'manipulating'

    def __init__(self, mode):
        super().__init__(outcomes=['changed', 'failed'])
        self._run = CapabilityRequest(mode, type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('changed', 'failed')
