"""ObjectActionState: run an action of the simulated robot on the object template the operator chose."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class ObjectActionState(EventState):
    """
    Runs one action of the simulated robot on an object template, e.g. picking it up.

    The robot checks the template id as ATLAS would: it must name an object of the scene
    within reach (a wrong id fails with the reason).

    -- capability   string   Action name as in the system config, e.g. 'pickup_object'.

    ># template_id  int      The object template (the operator's choice).

    <= completed             The robot reports the action completed.
    <= failed                The robot reports it failed, or no simulator answered.
    """

    def __init__(self, capability):
        super().__init__(outcomes=['completed', 'failed'], input_keys=['template_id'])
        self._run = CapabilityRequest(capability, type(self).__name__)

    def on_enter(self, userdata):
        self._run.start(userdata={'template_id': userdata.template_id})

    def execute(self, userdata):
        return self._run.outcome('completed', 'failed')
