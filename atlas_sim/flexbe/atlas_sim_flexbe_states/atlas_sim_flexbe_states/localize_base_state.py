"""LocalizeBaseState: the mobile manipulator's localization, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class LocalizeBaseState(EventState):
    """
    Localizes the mobile base (the simulator's localize capability).

    #> pose         object   The robot pose (in the simulator: what it reported).

    <= localized             The robot knows where it is.
    <= failed                Localization failed.
    """

    def __init__(self):
        super().__init__(outcomes=['localized', 'failed'], output_keys=['pose'])
        self._run = CapabilityRequest('localize', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        outcome = self._run.outcome('localized', 'failed')
        if outcome == 'localized':
            userdata.pose = self._run.report()
        return outcome
