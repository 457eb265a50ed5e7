"""PlanEndeffectorPoseState: Team ViGIR's end-effector motion planning, on the simulator."""

from flexbe_core import EventState, Logger

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class PlanEndeffectorPoseState(EventState):
    """
    Plans a motion of one hand to a target pose (the simulator's pregrasp_plan capability).

    -- hand         string   Which hand ('left' or 'right').

    ># target_pose  object   Pose the end effector should reach.

    <= planned               A plan was found.
    <= failed                No plan was found.
    """

    def __init__(self, hand='right'):
        super().__init__(outcomes=['planned', 'failed'], input_keys=['target_pose'])
        self._hand = hand
        self._run = CapabilityRequest('pregrasp_plan', type(self).__name__)

    def on_enter(self, userdata):
        Logger.loginfo(f'PlanEndeffectorPoseState: planning {self._hand} hand to {userdata.target_pose}')
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('planned', 'failed')
