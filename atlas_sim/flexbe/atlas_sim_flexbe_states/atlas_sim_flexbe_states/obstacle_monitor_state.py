"""ObstacleMonitorState: the mobile manipulator's obstacle sensor, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class ObstacleMonitorState(EventState):
    """
    Returns once the simulated mobile manipulator detects an obstacle (sensor obstacle_detected).

    <= detected              An obstacle is detected.
    """

    def __init__(self):
        super().__init__(outcomes=['detected'])
        self._run = CapabilityRequest('obstacle_detected', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('detected', None)  # nothing detected yet: keep waiting
