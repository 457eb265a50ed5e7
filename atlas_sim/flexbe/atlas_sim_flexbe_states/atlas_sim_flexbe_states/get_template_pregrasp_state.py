"""GetTemplatePregraspState: Team ViGIR's pregrasp pose lookup for an object template, on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class GetTemplatePregraspState(EventState):
    """
    Gets the pregrasp pose of the selected object template (the simulator's pregrasp_pose capability).

    -- preference   int      Index of the preferred grasp of the template.

    ># template_id  int      The object template (the operator's choice).

    #> pre_grasp    object   The pregrasp pose (in the simulator: what it reported).

    <= done                  The pose is available.
    <= failed                The lookup failed.
    <= not_available         The template has no such grasp.
    """

    def __init__(self, preference=0):
        super().__init__(outcomes=['done', 'failed', 'not_available'],
                         input_keys=['template_id'], output_keys=['pre_grasp'])
        self._preference = preference
        self._run = CapabilityRequest('pregrasp_pose', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start(userdata={'template_id': userdata.template_id})

    def execute(self, userdata):
        outcome = self._run.outcome('done', 'failed')
        if outcome == 'done':
            userdata.pre_grasp = self._run.report()
        return outcome
