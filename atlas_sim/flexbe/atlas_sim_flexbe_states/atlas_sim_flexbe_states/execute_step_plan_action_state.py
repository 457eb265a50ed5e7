"""ExecuteStepPlanActionState: Team ViGIR's footstep plan execution, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class ExecuteStepPlanActionState(EventState):
    """
    Walks the planned footsteps (the simulator's footstep_execution capability).

    <= finished              All steps were taken.
    <= failed                Walking the plan failed.
    """

    def __init__(self):
        super().__init__(outcomes=['finished', 'failed'])
        self._run = CapabilityRequest('footstep_execution', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('finished', 'failed')
