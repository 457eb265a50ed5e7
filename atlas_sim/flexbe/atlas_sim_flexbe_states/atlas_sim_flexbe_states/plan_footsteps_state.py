"""PlanFootstepsState: Team ViGIR's footstep planning, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class PlanFootstepsState(EventState):
    """
    Plans footsteps to the step goal (the simulator's footstep_plan capability).

    -- mode         string   Planning mode, one of the class constants.

    <= planned               A footstep plan was found.
    <= failed                No plan was found.
    """

    MODE_STEP_NO_COLLISION = 'step_no_collision'
    MODE_STEP_2D = 'step_2d'
    MODE_STEP_3D = 'step_3d'
    MODE_WALK = 'walk'

    def __init__(self, mode):
        super().__init__(outcomes=['planned', 'failed'])
        self._run = CapabilityRequest('footstep_plan', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('planned', 'failed')
