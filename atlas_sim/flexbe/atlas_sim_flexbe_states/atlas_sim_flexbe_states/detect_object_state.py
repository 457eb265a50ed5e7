"""DetectObjectState: the mobile manipulator's object detection, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class DetectObjectState(EventState):
    """
    Looks for an object of a class (the simulator's detect_object capability).

    -- object_class string   What to look for, e.g. "cup".

    #> object_pose  object   Where it is (in the simulator: what it reported).

    <= found                 The object was detected.
    <= not_found             No such object was detected.
    """

    def __init__(self, object_class):
        super().__init__(outcomes=['found', 'not_found'], output_keys=['object_pose'])
        self._run = CapabilityRequest('detect_object', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        outcome = self._run.outcome('found', 'not_found')
        if outcome == 'found':
            userdata.object_pose = self._run.report()
        return outcome
