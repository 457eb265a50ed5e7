"""A client of ``/behavior_synthesis`` shared by send-goal, demo, execute and the web GUI."""

from __future__ import annotations

import functools
import threading
import time
from dataclasses import dataclass, field

import yaml
from unique_identifier_msgs.msg import UUID

from respec.vocabulary.errors import ErrorCode
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES
from sm_generation.state_machine import StateMachine
from synthesis_manager.client_shares import new_origin, tagged_goal_id
from synthesis_manager.limits import check_texts
from synthesis_manager.requests import InvalidRequestError
from synthesis_manager.ros.action_client import GOAL_RESPONSE_GRACE, RaceFreeActionClient
from synthesis_manager.ros.cnu_interface import load_flexbe_synthesis_interface
from synthesis_manager.ros.conversions import error_name, msg_to_sections, msg_to_state_dict
from synthesis_msgs.action import BehaviorSynthesis
from synthesis_msgs.msg import BehaviorSynthesisRequest, LTLSpecification, SynthesisOptions

ACTION_NAME = 'behavior_synthesis'
# The two action interfaces of the server.
ACTIONS = ('behavior_synthesis', 'flexbe_synthesis')


def action_type(action_name: str):
    """The type of one of ACTIONS, as a server in this environment offers it (FlexBESynthesis:
    CNU's when importable); other names are served with BehaviorSynthesis."""
    if action_name == 'flexbe_synthesis':
        return load_flexbe_synthesis_interface().action_type
    return BehaviorSynthesis


GOAL_STATUS_NAMES = {4: 'SUCCEEDED', 5: 'CANCELED', 6: 'ABORTED'}
GOAL_STATUS_UNKNOWN = 0
RESULT_EXPIRED = ('the server no longer knows this goal: its result was asked for after its result_retention, '
                  'or the server restarted; send the goal again')


@dataclass
class SynthesisOutcome:
    """What a goal ended with, in plain Python types."""

    error_code: int
    error_name: str
    message: str
    states: list[dict] = field(default_factory=list)
    ltl_specification: dict = field(default_factory=dict)
    automaton: dict = field(default_factory=dict)
    seconds: float = 0.0
    goal_status: str = ''

    @property
    def succeeded(self) -> bool:
        return self.error_name == ErrorCode.SUCCESS

    @functools.cached_property
    def machine(self) -> StateMachine | None:
        """The result's state machine as its tree, built once (None without one): the one place a
        StateInstantiation list from the wire becomes the tree. Raises SMGenerationError if the
        server sent a list that is no runnable machine."""
        return StateMachine.from_instantiations(self.states) if self.states else None

    def to_dict(self) -> dict:
        return {'error_code': self.error_code, 'error_name': self.error_name,
                'message': self.message, 'states': self.states,
                'ltl_specification': self.ltl_specification, 'automaton': self.automaton,
                'seconds': round(self.seconds, 4), 'goal_status': self.goal_status}


def make_goal(system: str, initial_conditions, goals, sm_outcomes=DEFAULT_SM_OUTCOMES,
              option: str | None = None, name: str = '', ltl_specification: dict | None = None,
              unordered: bool = False, timeout: float = 0.0) -> BehaviorSynthesis.Goal:
    """Build a goal; list arguments are joined the original way (comma-separated)."""
    join = lambda names: names if isinstance(names, str) else ', '.join(names)  # noqa: E731
    request = BehaviorSynthesisRequest(
        system=system, initial_condition=join(initial_conditions), goal=join(goals),
        sm_outcomes=list(sm_outcomes), name=name, unordered_goals=unordered, timeout=float(timeout),
        ltl_specification=LTLSpecification(**(ltl_specification or {})))
    options = SynthesisOptions()
    if option:
        setattr(options, option, True)
    return BehaviorSynthesis.Goal(request=request, synthesis_options=options)


def make_flexbe_goal(system: str, initial_conditions, goals, sm_outcomes=DEFAULT_SM_OUTCOMES,
                     option: str | None = None, name: str = '', timeout: float = 0.0,
                     unordered: bool = False):
    """A FlexBESynthesis goal of the type offered (CNU's interface): the options travel as YAML."""
    as_list = lambda names: [names] if isinstance(names, str) else list(names)  # noqa: E731
    options = {name: True for name in (option,) if name}
    if unordered:
        options['unordered_goals'] = True
    interface = load_flexbe_synthesis_interface()
    request = interface.request_type(
        system_name=system, initial_conditions=as_list(initial_conditions), goals=as_list(goals),
        sm_outcomes=list(sm_outcomes), spec_name=name, synthesis_timeout_s=float(timeout))
    return interface.action_type.Goal(request=request,
                                      synthesis_options=yaml.safe_dump(options) if options else '')


def automaton_to_dict(automaton) -> dict:
    return {'output_variables': list(automaton.output_variables),
            'input_variables': list(automaton.input_variables),
            'initial_states': list(automaton.initial_states),
            'states': [{'name': s.name, 'output_valuation': [bool(v) for v in s.output_valuation],
                        'input_valuation': [bool(v) for v in s.input_valuation],
                        'transitions': list(s.transitions), 'rank': int(s.rank)}
                       for s in automaton.automaton]}


def outcome_from_result(result, seconds: float) -> SynthesisOutcome:
    """A result of either action; FlexBESynthesis results carry CNU's codes and `messages`."""
    states = [msg_to_state_dict(s) for s in result.states]
    if 'messages' in result.get_fields_and_field_types():  # FlexBESynthesis, either type
        return SynthesisOutcome(
            error_code=result.error_code.value, error_name=error_name(result.error_code.value,
                                                                      type(result.error_code)),
            message='\n'.join(result.messages), states=states, seconds=seconds)
    return SynthesisOutcome(
        error_code=result.error_code.value, error_name=error_name(result.error_code.value),
        message=result.error_code.message, states=states,
        ltl_specification=msg_to_sections(result.ltl_specification),
        automaton=automaton_to_dict(result.automaton), seconds=seconds)


def outcome_from_response(response, seconds: float) -> SynthesisOutcome:
    """A result request's answer; TIMEOUT when the server no longer knew the goal (rclpy then
    answers status UNKNOWN with an empty result, whose error code 0 is no code of ours)."""
    if response.status == GOAL_STATUS_UNKNOWN:
        return SynthesisOutcome(ErrorCode.TIMEOUT.number, ErrorCode.TIMEOUT, RESULT_EXPIRED, seconds=seconds,
                                goal_status='UNKNOWN')
    outcome = outcome_from_result(response.result, seconds)
    outcome.goal_status = GOAL_STATUS_NAMES.get(response.status, str(response.status))
    return outcome


# Goal states after which the server has a result to give.
_FINISHED_STATES = tuple(GOAL_STATUS_NAMES)
# Ask for a result again this long after the status said the goal finished (or anyway
# after RESULT_REQUEST_RETRY): a result request or its response can be lost.
RESULT_GRACE = 5.0
RESULT_REQUEST_RETRY = 10.0
# A goal's server missing from the ROS graph this long is gone (killed, crashed): the goal
# ends SERVICE_UNAVAILABLE instead of waiting out its time limit. DDS leases are 1 s
# (ros/fastdds_loopback.xml), so a dead server leaves the graph within about 2 s.
SERVER_LOST_SECONDS = 2.5
LIVENESS_PERIOD = 0.25


class SynthesisClient:
    """Sends goals from a (spinning) node and waits for them in the calling thread.

    Every accepted goal gets its result: the action client registers each request before
    its response can arrive (rclpy#1123), and the result is asked for again when it is
    overdue (the server keeps it for its ``result_retention``).
    """

    def __init__(self, node, action_name: str = ACTION_NAME):
        """``action_name``: one of ACTIONS, or any name served with BehaviorSynthesis."""
        self.node = node
        self.action_name = action_name
        self.action_client = RaceFreeActionClient(node, action_type(action_name), action_name)
        # Every goal id says it comes from this client: the server's per-client share (client_shares.py).
        self.origin = new_origin()

    def wait_for_server(self, timeout: float = 10.0) -> bool:
        return self.action_client.wait_for_server(timeout_sec=timeout)

    def run(self, goal, feedback=None, cancel: threading.Event | None = None,
            timeout: float = 600.0) -> SynthesisOutcome:
        """Send ``goal``; call ``feedback(status, progress)``; cancel when ``cancel`` is set.

        A goal with a control character is answered INVALID_REQUEST here, unsent, as the server
        would answer it: a NUL must be caught before sending, because serialization cuts the
        string there and the server would run the rest (SUCCESS with half the task)."""
        started = time.monotonic()
        try:
            check_texts(goal, 'goal')
        except InvalidRequestError as refused:
            return SynthesisOutcome(refused.code.number, str(refused.code), str(refused))
        on_feedback = (lambda msg: feedback(msg.feedback.status, msg.feedback.progress)) if feedback else None
        goal_id = UUID(uuid=list(tagged_goal_id(self.origin)))
        handle = self._accepted(self.action_client.send_goal_async(goal, feedback_callback=on_feedback,
                                                                   goal_uuid=goal_id), goal_id, started, timeout)
        if handle is None:
            return self.server_lost(time.monotonic() - started)
        if not handle.accepted:
            # The server rejects goals only in a flood (see BehaviorSynthesisServer.admit_goal).
            return SynthesisOutcome(-5, 'BUSY', 'the server rejected the goal: too many goals are in '
                                    'progress (twice max_active_goals); try again later')
        done = threading.Event()
        requests = []

        def request_result():
            future = self.action_client._get_result_async(handle)  # noqa: SLF001 - rclpy has no public way to ask for a result twice
            future.add_done_callback(lambda _: done.set())
            requests.append((future, time.monotonic()))

        request_result()
        cancel_sent = False
        finished_seen = None
        server_seen = checked = time.monotonic()
        while not done.wait(0.02):
            now = time.monotonic()
            if now - checked >= LIVENESS_PERIOD:
                checked = now
                if self.action_client.server_is_ready():
                    server_seen = now
                elif now - server_seen >= SERVER_LOST_SECONDS:
                    return self.server_lost(now - started)
            if cancel is not None and cancel.is_set() and not cancel_sent:
                handle.cancel_goal_async()
                cancel_sent = True
            if now - started > timeout:
                handle.cancel_goal_async()
                raise TimeoutError(f'no result within {timeout:g} s')
            if handle.status in _FINISHED_STATES and finished_seen is None:
                finished_seen = now
            last_request = requests[-1][1]
            if ((finished_seen is not None and now - max(finished_seen, last_request) > RESULT_GRACE)
                    or now - last_request > RESULT_REQUEST_RETRY):
                request_result()
        # Requests still pending are left to complete: dropping them would make their late
        # responses "unexpected".
        answers = [future.result() for future, _ in requests if future.done()]
        response = next((answer for answer in answers if answer.status != GOAL_STATUS_UNKNOWN), answers[0])
        return outcome_from_response(response, time.monotonic() - started)

    def _accepted(self, sent, goal_id, started: float, timeout: float):
        """The goal handle of the goal request ``sent``, or None when the server left the ROS
        graph (killed, crashed, stopped) before answering it: a stalled server must not hold a
        caller until its timeout."""
        answered = threading.Event()
        sent.add_done_callback(lambda _: answered.set())
        server_seen = time.monotonic()
        try:
            while not answered.wait(LIVENESS_PERIOD):
                now = time.monotonic()
                if self.action_client.server_is_ready():
                    server_seen = now
                elif now - server_seen >= SERVER_LOST_SECONDS:
                    return None
                if now - started > timeout:
                    raise TimeoutError(f'the goal was not accepted within {timeout:g} s')
                if now - started > GOAL_RESPONSE_GRACE and self.action_client.accepted_without_response(sent):
                    break
            return sent.result()
        finally:
            self.action_client.stop_awaiting(goal_id)

    def server_lost(self, seconds: float) -> SynthesisOutcome:
        """The outcome of a goal whose server left the ROS graph before answering."""
        return SynthesisOutcome(
            ErrorCode.SERVICE_UNAVAILABLE.number, ErrorCode.SERVICE_UNAVAILABLE,
            f'the {self.node.resolve_service_name(self.action_name)} action server went away while the goal '
            'was in progress (gone from '
            f'the ROS graph for {SERVER_LOST_SECONDS:g} s: killed or crashed); start it again and send '
            'the goal again', seconds=seconds)
