"""ChangeControlModeActionState: Team ViGIR's ATLAS control-mode change, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class ChangeControlModeActionState(EventState):
    """
    Changes ATLAS's control mode (the simulator's control-mode capability of the same name).

    -- target_mode  string   A class constant or its value (ChangeControlModeActionState.STAND or "stand").

    <= changed               The robot is in the target mode.
    <= failed                The mode change failed.
    """

    # BDI control modes by their ATLAS names; each is the simulator capability of that name.
    STAND_PREP = 'stand_prep'
    STAND = 'stand'
    MANIPULATE = 'manipulate'
    STEP = 'step'
    WALK = 'walk'

    def __init__(self, target_mode):
        super().__init__(outcomes=['changed', 'failed'])
        self._run = CapabilityRequest(target_mode, type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('changed', 'failed')
