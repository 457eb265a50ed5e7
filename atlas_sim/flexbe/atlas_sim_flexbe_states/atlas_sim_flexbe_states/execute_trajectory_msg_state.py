"""ExecuteTrajectoryMsgState: Team ViGIR's arm trajectory execution, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class ExecuteTrajectoryMsgState(EventState):
    """
    Executes an arm trajectory with one of ATLAS's trajectory controllers.

    The simulator knows one arm trajectory, moving the right arm to the pregrasp posture
    (its pregrasp capability); other controllers fail with a message saying so.

    -- controller   string   Trajectory controller, one of the class constants.

    <= done                  The trajectory was executed.
    <= failed                It could not be executed.
    """

    CONTROLLER_LEFT_ARM = 'left_arm_traj_controller'
    CONTROLLER_RIGHT_ARM = 'right_arm_traj_controller'
    CONTROLLER_PELVIS = 'pelvis_traj_controller'
    CONTROLLER_TORSO = 'torso_traj_controller'
    CONTROLLER_NECK = 'neck_traj_controller'

    # Controller -> simulator capability whose motion it executes.
    SIMULATED_CONTROLLERS = {CONTROLLER_RIGHT_ARM: 'pregrasp'}

    def __init__(self, controller):
        super().__init__(outcomes=['done', 'failed'])
        self._controller = controller
        self._run = CapabilityRequest(self.SIMULATED_CONTROLLERS.get(controller), type(self).__name__)

    def on_enter(self, userdata):
        self._run.start(f'ExecuteTrajectoryMsgState: the simulator has no trajectory for {self._controller}')

    def execute(self, userdata):
        return self._run.outcome('done', 'failed')
