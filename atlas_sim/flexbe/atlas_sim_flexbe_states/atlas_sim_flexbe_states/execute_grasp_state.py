"""ExecuteGraspState: the mobile manipulator's grasp execution, on the simulator."""

from flexbe_core import EventState, Logger

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class ExecuteGraspState(EventState):
    """
    Executes a planned grasp (the simulator's grasp capability).

    ># grasp        object   The grasp plan.

    <= grasped               The object is in the gripper.
    <= failed                The grasp failed.
    <= slipped               The object slipped out.
    """

    def __init__(self):
        super().__init__(outcomes=['grasped', 'failed', 'slipped'], input_keys=['grasp'])
        self._run = CapabilityRequest('grasp', type(self).__name__)

    def on_enter(self, userdata):
        Logger.loginfo(f'ExecuteGraspState: executing grasp {userdata.grasp}')
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('grasped', 'failed')
