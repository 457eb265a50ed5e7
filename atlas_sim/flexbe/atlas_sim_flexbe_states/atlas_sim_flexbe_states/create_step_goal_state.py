"""CreateStepGoalState: Team ViGIR's footstep goal creation, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class CreateStepGoalState(EventState):
    """
    Creates the goal for footstep planning from the target pose (the simulator's footstep_goal capability).

    -- pose_is_pelvis  bool  Whether the target pose is the pelvis pose (else the feet center).

    ># target_pose  object   Where to go: x, y, yaw (the operator's input).

    <= done                  The step goal was created.
    <= failed                It could not be created.
    """

    def __init__(self, pose_is_pelvis=False):
        super().__init__(outcomes=['done', 'failed'], input_keys=['target_pose'])
        self._run = CapabilityRequest('footstep_goal', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start(userdata={'target_pose': userdata.target_pose})

    def execute(self, userdata):
        return self._run.outcome('done', 'failed')
