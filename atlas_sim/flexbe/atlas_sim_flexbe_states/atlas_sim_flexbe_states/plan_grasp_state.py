"""PlanGraspState: the mobile manipulator's grasp planning, on the simulator."""

from flexbe_core import EventState, Logger

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class PlanGraspState(EventState):
    """
    Plans a grasp of the detected object (the simulator's plan_grasp capability).

    ># object_pose  object   Where the object is.

    #> grasp        object   The grasp plan (in the simulator: what it reported).

    <= planned               A grasp was planned.
    <= failed                No grasp was found.
    """

    def __init__(self):
        super().__init__(outcomes=['planned', 'failed'], input_keys=['object_pose'], output_keys=['grasp'])
        self._run = CapabilityRequest('plan_grasp', type(self).__name__)

    def on_enter(self, userdata):
        Logger.loginfo(f'PlanGraspState: planning a grasp of the object at {userdata.object_pose}')
        self._run.start()

    def execute(self, userdata):
        outcome = self._run.outcome('planned', 'failed')
        if outcome == 'planned':
            userdata.grasp = self._run.report()
        return outcome
