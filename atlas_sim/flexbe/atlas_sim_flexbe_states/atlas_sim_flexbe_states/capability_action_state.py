"""CapabilityActionState: run any capability of the simulated robot by name."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class CapabilityActionState(EventState):
    """
    Runs one capability (control mode or action) of the simulated robot.

    The generic state behind the behaviors of atlas_sim_flexbe_behaviors.

    -- capability   string   Capability name as in the system config, e.g. 'pickup_object'.

    <= completed             The robot reports the capability completed.
    <= failed                The robot reports it failed, or no simulator answered.
    """

    def __init__(self, capability):
        super().__init__(outcomes=['completed', 'failed'])
        self._run = CapabilityRequest(capability, type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('completed', 'failed')
