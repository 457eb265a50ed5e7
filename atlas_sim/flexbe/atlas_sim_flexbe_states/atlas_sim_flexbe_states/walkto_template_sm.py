"""WalktoTemplateSM: walking to the selected object template (Team ViGIR's behavior), on the simulator."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class WalktoTemplateSM(EventState):
    """
    Walks ATLAS to the selected object template (the simulator's approach_object capability).

    Team ViGIR's 'Walk to Template' behavior, here one state, as the system config uses it.

    ># template_id  int      The object template to walk to (the operator's choice).

    <= finished              ATLAS stands at the template.
    <= failed                Walking failed.
    <= aborted               The walk was given up.
    """

    def __init__(self):
        super().__init__(outcomes=['finished', 'failed', 'aborted'], input_keys=['template_id'])
        self._run = CapabilityRequest('approach_object', type(self).__name__)

    def on_enter(self, userdata):
        self._run.start(userdata={'template_id': userdata.template_id})

    def execute(self, userdata):
        return self._run.outcome('finished', 'failed')
