"""One capability run on the simulator node, through FlexBE's ProxyActionClient.

The simulator node (atlas_sim) serves one ExecuteCapability action per capability under
``atlas_sim/capabilities/<capability>``: FlexBE's proxy keeps one goal per action name, and
states running concurrently (a ConcurrencyContainer) each need their own. Nothing here
blocks in ``execute``: the goal is sent on enter and the result is polled.

A result the robot sent can be lost on the way (4 of 100 onboard runs of the 5-goal behavior,
each on a different capability: the goal's status said it had finished, the result never came).
So when the goal's status has said "finished" for ``RESULT_RETRY`` seconds without a result,
the result is asked for again (the action server keeps it); and a result that still never
arrives ends the state in its failure outcome after ``RESULT_TIMEOUT`` seconds, naming the
capability, instead of holding the behavior forever.
"""

import json
import time

from action_msgs.msg import GoalStatus
from flexbe_core import Logger
from flexbe_core.proxy import ProxyActionClient

from atlas_sim.simulator.node_names import CAPABILITY_ACTION_PREFIX
from respec.vocabulary.naming import COMPLETED  # the ExecuteCapability result outcome meaning success
from synthesis_msgs.action import ExecuteCapability

# How long on_enter waits for the simulator's action server the first time (discovery).
SERVER_WAIT = 5.0
# Wall-clock seconds a capability may take before the state gives up on its result: every
# capability of the simulated robot completes within a few seconds of robot time.
RESULT_TIMEOUT = 60.0
# Seconds after the goal's status said it finished before its result is asked for again.
RESULT_RETRY = 2.0
_FINISHED = (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_ABORTED, GoalStatus.STATUS_CANCELED)


def capability_goal(capability, userdata=None):
    """The ExecuteCapability goal: the capability and the userdata values as JSON text."""
    userdata = dict(userdata or {})
    return ExecuteCapability.Goal(capability=capability, userdata_keys=list(userdata),
                                  userdata_values=[json.dumps(value, default=str) for value in userdata.values()])


class CapabilityRequest:
    """Runs ``capability`` (None: the state's parameters name nothing the simulator can do)."""

    def __init__(self, capability, state_name, result_timeout=RESULT_TIMEOUT):
        self.capability = capability
        self.state_name = state_name
        self.result_timeout = result_timeout
        self.result = None  # the ExecuteCapability result once it arrived
        self._failure = None
        self._sent_at = None
        self._finished_at = None    # when the goal's status was first seen finished
        self._asked_again_at = None
        self._result_asked_again = None
        self._topic = CAPABILITY_ACTION_PREFIX + capability if capability else None

    def start(self, unsupported_reason='', userdata=None):
        """Send the goal (on_enter); ``userdata``: the keys the robot needs, e.g. ``{'template_id': 1}``."""
        self.result, self._failure = None, None
        self._finished_at = self._asked_again_at = self._result_asked_again = None
        if not self._topic:
            self._failure = unsupported_reason or f'{self.state_name}: nothing the simulator can do'
            Logger.logwarn(self._failure)
            return
        try:
            # Registered on first use, where waiting for discovery is expected (a client made
            # while the behavior is built would report the not yet discovered server as an error).
            ProxyActionClient.setupClient(self._topic, ExecuteCapability, wait_duration=SERVER_WAIT)
            ProxyActionClient.send_goal(self._topic, capability_goal(self.capability, userdata),
                                        wait_duration=SERVER_WAIT)
            self._sent_at = time.monotonic()
        except Exception as error:  # noqa: BLE001 - no server, a wrong type: the state says so
            self._failure = f'{self.state_name}: could not request {self.capability}: {error}'
            Logger.logwarn(self._failure)

    def outcome(self, completed, failed):
        """``completed``/``failed`` once the robot answered, None while it runs (execute)."""
        if self._failure:
            return failed
        if ProxyActionClient.has_result(self._topic):
            self.result = ProxyActionClient.get_result(self._topic)
            ProxyActionClient.remove_result(self._topic)
        elif self._result_asked_again is not None:
            self.result = self._result_asked_again
        else:
            self._ask_again_if_lost()
            if time.monotonic() - self._sent_at < self.result_timeout:
                return None
            self._failure = (f'{self.state_name}: no result for {self.capability} within '
                             f'{self.result_timeout:g} s; giving up on it')
            Logger.logerr(self._failure)
            ProxyActionClient.cancel(self._topic)
            return failed
        if self.result.outcome == COMPLETED:
            return completed
        Logger.logwarn(f'{self.state_name}: {self.capability} failed: {self.result.reason}')
        return failed

    def _ask_again_if_lost(self):
        """Ask for the result again when the goal's status has said "finished" for RESULT_RETRY
        seconds (and again every RESULT_RETRY seconds). flexbe_core 2.3.3's proxy has no public
        accessor for the goal's handle: its ``_current_goal`` future is read."""
        goal = ProxyActionClient._current_goal.get(self._topic)  # noqa: SLF001 - flexbe_core keeps running goals in a class attribute only
        handle = goal.result() if goal is not None and goal.done() else None
        if handle is None or handle.status not in _FINISHED:
            return
        now = time.monotonic()
        self._finished_at = self._finished_at or now
        if now - max(self._finished_at, self._asked_again_at or 0.0) < RESULT_RETRY:
            return
        self._asked_again_at = now
        Logger.logwarn(f'{self.state_name}: {self.capability} finished {now - self._finished_at:.0f} s ago '
                       'but its result has not arrived; asking for it again')
        handle.get_result_async().add_done_callback(self._got_result_again)

    def _got_result_again(self, future):
        response = future.result()
        if response is not None:
            self._result_asked_again = response.result

    def report(self):
        """What the simulator reported, for output userdata (it computes no poses or plans)."""
        return {'capability': self.capability, 'outcome': self.result.outcome, 'stamp': self.result.stamp}
