"""synthesis_msgs: every interface field for field, and a live service/action round trip."""

import time

import pytest

from synthesis_msgs.action import BehaviorSynthesis
from synthesis_msgs.msg import (AutomatonState, BehaviorSynthesisRequest, FSAutomaton,
                                LTLSpecification, OutcomeCondition, StateInstantiation,
                                SynthesisErrorCodes, SynthesisOptions)
from synthesis_msgs.srv import GenerateFlexBESM, GenerateLTLSpecification, SynthesizeAutomaton
from synthesis_manager.ros.harness import wait_for

pytestmark = pytest.mark.ros

FLEXBE_STATE_INSTANTIATION = {
    'state_path': 'string', 'state_class': 'string', 'initial_state_name': 'string',
    'input_keys': 'sequence<string>', 'output_keys': 'sequence<string>',
    'cond_outcome': 'sequence<string>',
    'cond_transition': 'sequence<synthesis_msgs/OutcomeCondition>',
    'behavior_class': 'string', 'parameter_names': 'sequence<string>',
    'parameter_values': 'sequence<string>', 'position': 'float[2]',
    'outcomes': 'sequence<string>', 'transitions': 'sequence<string>',
    'autonomy': 'sequence<int8>', 'userdata_keys': 'sequence<string>',
    'userdata_remapping': 'sequence<string>',
}

ORIGINAL_ERROR_CODES = {
    'SUCCESS': 1, 'FAILURE': 99999, 'BEHAVIOR_SYNTHESIS_FAILED': -1, 'PREEMPTED': -9,
    'LTL_SPEC_COMPILATION_FAILED': -10, 'SYNTHESIS_FAILED': -20, 'SPEC_UNSYNTHESIZABLE': -21,
    'SM_GENERATION_FAILED': -30, 'NO_SYSTEMS_FILE': -31, 'NO_SYSTEM_CONFIG': -32,
    'SYSTEM_CONFIG_NOT_FOUND': -33, 'CONFIG_FILE_INVALID': -34, 'CONFIG_AUTONOMY_INVALID': -35,
    'CONFIG_VARIABLE_CONFIG_INVALID': -36, 'AUTOMATON_INVALID': -37,
    'AUTOMATON_NO_INITIAL_STATE': -38, 'AUTOMATON_NEXT_STATE_INVALID': -39,
    'AUTOMATON_INPUT_VALUATION_INVALID': -40, 'AUTOMATON_OUTPUT_VALUATION_INVALID': -41,
    'CONFIG_USERDATA_INVALID': -42,
}


def fields(message_type):
    return message_type.get_fields_and_field_types()


def assert_contains_fields(message_type, expected):
    actual = fields(message_type)
    for name, type_name in expected.items():
        assert actual.get(name) == type_name, f'{message_type.__name__}.{name}'


def test_state_instantiation_is_field_identical_to_flexbe():
    assert list(fields(StateInstantiation)) == list(FLEXBE_STATE_INSTANTIATION)
    assert fields(StateInstantiation) == FLEXBE_STATE_INSTANTIATION
    assert fields(OutcomeCondition) == {'state_name': 'sequence<string>',
                                        'state_outcome': 'sequence<string>'}
    assert StateInstantiation.CLASS_STATEMACHINE == ':STATEMACHINE'
    assert StateInstantiation.CLASS_CONCURRENCY == ':CONCURRENCY'
    assert StateInstantiation.CLASS_PRIORITY == ':PRIORITY'
    assert StateInstantiation.CLASS_BEHAVIOR == ':BEHAVIOR'
    assert StateInstantiation.CLASS_OUTCOME == ':OUTCOME'


def test_error_codes_keep_every_original_constant():
    for name, value in ORIGINAL_ERROR_CODES.items():
        assert getattr(SynthesisErrorCodes, name) == value, name
    assert fields(SynthesisErrorCodes)['value'] == 'int32'
    values = [v for k, v in vars(SynthesisErrorCodes).items() if k.isupper() and isinstance(v, int)]
    assert len(values) == len(set(values)), 'error codes must be distinct'


def test_original_messages_keep_their_fields():
    ltl_sections = ['sys_props', 'env_props', 'sys_init', 'env_init', 'sys_trans', 'env_trans',
                    'sys_liveness', 'env_liveness']
    assert_contains_fields(LTLSpecification, {s: 'sequence<string>' for s in ltl_sections})
    assert_contains_fields(SynthesisOptions, {'ltl_compilation_only': 'boolean',
                                              'ltl_synthesis_only': 'boolean',
                                              'ltl_steps_only': 'boolean'})
    assert_contains_fields(AutomatonState, {
        'name': 'string', 'output_valuation': 'sequence<boolean>',
        'input_valuation': 'sequence<boolean>', 'transitions': 'sequence<string>',
        'rank': 'uint8'})
    assert_contains_fields(FSAutomaton, {
        'output_variables': 'sequence<string>', 'input_variables': 'sequence<string>',
        'automaton': 'sequence<synthesis_msgs/AutomatonState>'})
    assert_contains_fields(BehaviorSynthesisRequest, {
        'initial_condition': 'string', 'goal': 'string', 'sm_outcomes': 'sequence<string>',
        'system': 'string', 'name': 'string',
        'ltl_specification': 'synthesis_msgs/LTLSpecification'})
    assert (BehaviorSynthesisRequest.ATLAS, BehaviorSynthesisRequest.YOUBOT,
            BehaviorSynthesisRequest.BAXTER, BehaviorSynthesisRequest.OTHER) == (
        'atlas', 'youbot', 'baxter', 'other')


def test_services_and_action_keep_their_fields():
    assert_contains_fields(GenerateLTLSpecification.Request, {
        'system': 'string', 'goals': 'sequence<string>', 'initial_conditions': 'sequence<string>',
        'sm_outcomes': 'sequence<string>'})
    assert_contains_fields(GenerateLTLSpecification.Response, {
        'ltl_specification': 'synthesis_msgs/LTLSpecification',
        'error_code': 'synthesis_msgs/SynthesisErrorCodes'})
    assert_contains_fields(SynthesizeAutomaton.Request, {
        'ltl_specification': 'synthesis_msgs/LTLSpecification', 'spec_name': 'string'})
    assert_contains_fields(SynthesizeAutomaton.Response, {
        'synthesizable': 'boolean', 'automaton': 'synthesis_msgs/FSAutomaton',
        'error_code': 'synthesis_msgs/SynthesisErrorCodes'})
    assert_contains_fields(GenerateFlexBESM.Request, {
        'automaton': 'synthesis_msgs/FSAutomaton', 'system': 'string'})
    assert_contains_fields(GenerateFlexBESM.Response, {
        'state_definition': 'sequence<synthesis_msgs/StateInstantiation>',
        'error_code': 'synthesis_msgs/SynthesisErrorCodes'})
    assert_contains_fields(BehaviorSynthesis.Goal, {
        'request': 'synthesis_msgs/BehaviorSynthesisRequest',
        'synthesis_options': 'synthesis_msgs/SynthesisOptions'})
    assert_contains_fields(BehaviorSynthesis.Result, {
        'error_code': 'synthesis_msgs/SynthesisErrorCodes',
        'states': 'sequence<synthesis_msgs/StateInstantiation>'})
    assert_contains_fields(BehaviorSynthesis.Feedback, {'status': 'string', 'progress': 'float'})


# --- live round trips -------------------------------------------------------------------

def make_echo_service_node(context):
    from rclpy.node import Node

    node = Node('echo_synthesizer', context=context)

    def handle(request, response):
        response.synthesizable = True
        response.automaton.output_variables = list(request.ltl_specification.sys_props)
        response.automaton.automaton = [AutomatonState(name='0', output_valuation=[True],
                                                       transitions=['0'], rank=0)]
        response.error_code.value = SynthesisErrorCodes.SUCCESS
        return response

    node.create_service(SynthesizeAutomaton, 'ltl_synthesis', handle)
    return node


def test_service_round_trip_in_process(ros):
    from rclpy.node import Node

    ros.add_node(make_echo_service_node)
    client_node = ros.add_node(Node, 'client')
    client = client_node.create_client(SynthesizeAutomaton, 'ltl_synthesis')
    assert client.wait_for_service(timeout_sec=10.0)
    request = SynthesizeAutomaton.Request(
        ltl_specification=LTLSpecification(sys_props=['stand_a']), spec_name='x')
    response = wait_for(client.call_async(request))
    assert response.synthesizable
    assert list(response.automaton.output_variables) == ['stand_a']
    assert response.automaton.automaton[0].transitions == ['0']
    assert response.error_code.value == SynthesisErrorCodes.SUCCESS


def make_counting_action_node(context, steps=20, period=0.05):
    """An action server that counts to ``steps``, reporting progress, and honours cancel."""
    from rclpy.action import ActionServer, CancelResponse
    from rclpy.callback_groups import ReentrantCallbackGroup
    from rclpy.node import Node

    node = Node('counting_synthesis', context=context)

    def execute(goal_handle):
        for step in range(steps):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                return BehaviorSynthesis.Result(
                    error_code=SynthesisErrorCodes(value=SynthesisErrorCodes.PREEMPTED))
            goal_handle.publish_feedback(BehaviorSynthesis.Feedback(
                status=f'step {step}', progress=step / steps))
            time.sleep(period)
        goal_handle.succeed()
        state = StateInstantiation(state_path='/' + goal_handle.request.request.goal,
                                   state_class='TiltHeadState', outcomes=['done'],
                                   transitions=['finished'], autonomy=[0])
        return BehaviorSynthesis.Result(
            error_code=SynthesisErrorCodes(value=SynthesisErrorCodes.SUCCESS), states=[state])

    node.server = ActionServer(node, BehaviorSynthesis, 'behavior_synthesis', execute,
                               cancel_callback=lambda _: CancelResponse.ACCEPT,
                               callback_group=ReentrantCallbackGroup())
    return node


def send(ros, goal_text, steps):
    from rclpy.action import ActionClient
    from rclpy.node import Node

    ros.add_node(make_counting_action_node, steps=steps)
    client_node = ros.add_node(Node, 'action_client')
    client = ActionClient(client_node, BehaviorSynthesis, 'behavior_synthesis')
    assert client.wait_for_server(timeout_sec=10.0)
    feedback = []
    goal = BehaviorSynthesis.Goal(request=BehaviorSynthesisRequest(goal=goal_text, system='atlas'))
    handle = wait_for(client.send_goal_async(goal, feedback_callback=lambda m: feedback.append(m.feedback)))
    assert handle.accepted
    return handle, feedback


def test_action_round_trip_with_feedback_and_result(ros):
    handle, feedback = send(ros, 'look_down', steps=5)
    result = wait_for(handle.get_result_async()).result
    assert result.error_code.value == SynthesisErrorCodes.SUCCESS
    assert [s.state_path for s in result.states] == ['/look_down']
    assert feedback and feedback[0].status == 'step 0'
    assert [f.progress for f in feedback] == sorted(f.progress for f in feedback)


def test_action_cancel(ros):
    from action_msgs.msg import GoalStatus

    handle, feedback = send(ros, 'pickup_object', steps=400)
    deadline = time.monotonic() + 10
    while not feedback and time.monotonic() < deadline:
        time.sleep(0.02)
    assert feedback, 'no feedback before cancel'
    wait_for(handle.cancel_goal_async())
    outcome = wait_for(handle.get_result_async())
    assert outcome.status == GoalStatus.STATUS_CANCELED
    assert outcome.result.error_code.value == SynthesisErrorCodes.PREEMPTED
