"""GetTemplatePregraspState: Team ViGIR's pregrasp pose lookup for an object template, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class GetTemplatePregraspState(EventState):
    """
    Gets the pregrasp pose of the selected object template (the simulator's pregrasp_pose capability).

    ># preference   int      Index of the preferred grasp of the template.

    #> pre_grasp    object   The pregrasp pose (in the simulator: what it reported).

    <= done                  The pose is available.
    <= failed                The lookup failed.
    <= not_available         The template has no such grasp.
    """

    def __init__(self):
        super().__init__(outcomes=['done', 'failed', 'not_available'],
                         input_keys=['preference'], output_keys=['pre_grasp'])
        self._run = CapabilityRequest('pregrasp_pose', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        outcome = self._run.outcome('done', 'failed')
        if outcome == 'done':
            userdata.pre_grasp = self._run.report()
        return outcome
