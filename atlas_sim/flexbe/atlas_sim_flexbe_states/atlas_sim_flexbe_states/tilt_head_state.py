"""TiltHeadState: Team ViGIR's ATLAS head tilt, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class TiltHeadState(EventState):
    """
    Tilts ATLAS's head to a given angle.

    The simulator tilts the head 45 degrees down (its look_down capability); other angles
    fail with a message saying so.

    -- desired_tilt  float   Tilt in degrees, one of the class constants (negative: down).

    <= done                  The head reached the tilt.
    <= failed                The head could not be moved there.
    """

    UP_40 = 40.0
    UP_20 = 20.0
    STRAIGHT = 0.0
    DOWN_30 = -30.0
    DOWN_45 = -45.0
    DOWN_60 = -60.0

    # Tilt (degrees) -> simulator capability performing it.
    SIMULATED_TILTS = {DOWN_45: 'look_down'}

    def __init__(self, desired_tilt):
        super().__init__(outcomes=['done', 'failed'])
        self._desired_tilt = desired_tilt
        self._run = CapabilityRequest(self.SIMULATED_TILTS.get(desired_tilt), type(self).__name__)

    def on_enter(self, userdata):
        self._run.start(f'TiltHeadState: the simulator cannot tilt the head to {self._desired_tilt} degrees')

    def execute(self, userdata):
        return self._run.outcome('done', 'failed')
