"""A goal refused as impossible carries verified fixes in its result (issue 33 item 2): after
the message in BehaviorSynthesis' ``error_code.message``, and one per line after the failure in
CNU's FlexBESynthesis ``messages[]``; the compilation node's ``propose_repairs`` service finds
them (``ltl_specification.repair`` in a child process)."""

import json

import pytest

from suite_settings import suite_args
from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.suite import suite_node_factories

pytestmark = pytest.mark.ros

WRONG_ORDER = ('atlas', ['stand_prep'], ['look_down', 'stand_prep'])
FIRST_FIX = 'Suggested fix 1: Let the goals be achieved in any order (--unordered).'


def start_suite(ros, tmp_path, **overrides):
    from rclpy.node import Node

    # The server's default 3 s search ended before its fixes at load 7 on the 2 cores.
    overrides.setdefault('repair_time_budget', 10.0)
    for factory in suite_node_factories(suite_args(tmp_path, **overrides)):
        ros.add_node(factory)
    node = ros.add_node(Node, 'suggested_fixes_client')
    ours, cnus = SynthesisClient(node, 'behavior_synthesis'), SynthesisClient(node, 'flexbe_synthesis')
    assert ours.wait_for_server(timeout=10.0) and cnus.wait_for_server(timeout=10.0)
    return node, ours, cnus


def test_a_refused_goal_suggests_verified_fixes_in_both_results_and_the_first_one_works(ros, tmp_path):
    _, ours, cnus = start_suite(ros, tmp_path)
    result = ours.run(make_goal(*WRONG_ORDER), timeout=120)
    assert result.error_name == 'SPEC_UNSYNTHESIZABLE'
    message, _, fixes = result.message.partition('\n\nVerified fixes (each compiled and synthesized, and found '
                                                 'realizable; `behavior-synthesis repair` with the same task '
                                                 'lists more):\n')
    assert message.startswith('Goal 2 (stand_prep) can never be achieved')   # the diagnosis still leads
    lines = fixes.splitlines()
    assert lines[0] == f'  {FIRST_FIX}' and 1 < len(lines) <= 3
    assert lines[1] == '  Suggested fix 2: Achieve the goals in the order stand_prep, look_down.'
    cnu = cnus.run(make_flexbe_goal(*WRONG_ORDER), timeout=120)
    messages = cnu.message.split('\n')   # the client joins messages[] with newlines
    assert messages[0].startswith('SPEC_UNSYNTHESIZABLE: Goal 2 (stand_prep) can never be achieved')
    assert FIRST_FIX in messages and messages[-len(lines):] == [line.strip() for line in lines]
    # the fix is real: the same goal in any order succeeds
    fixed = ours.run(make_goal(*WRONG_ORDER, unordered=True), timeout=120)
    assert fixed.succeeded and fixed.states


def test_a_compiler_refusal_gets_a_change_of_the_robot_marked_as_such(ros, tmp_path):
    _, ours, _ = start_suite(ros, tmp_path)
    result = ours.run(make_goal('atlas', ['stand'], ['look_down', 'stand_prep']), timeout=120)
    assert result.error_name == 'INVALID_GOALS'
    assert ('Suggested fix 1: Change the robot: add the control-mode transition stand -> stand_prep '
            '(abstraction.control_modes.stand in config/atlas.yaml).') in result.message


def test_the_propose_repairs_service_answers_the_whole_search(ros, tmp_path):
    from synthesis_msgs.msg import LTLSpecification
    from synthesis_msgs.srv import ProposeRepairs

    node, _, _ = start_suite(ros, tmp_path)
    client = node.create_client(ProposeRepairs, 'propose_repairs')
    assert client.wait_for_service(timeout_sec=10.0)
    custom = LTLSpecification(env_props=['door_open'], sys_liveness=['door_open'])
    answer = client.call(ProposeRepairs.Request(system='atlas', goals=['look_down'], initial_conditions=['stand_prep'],
                                                custom_ltl=custom, max_proposals=2), timeout_sec=60)
    assert answer.error_code.value == 1, answer.error_code.message
    repairs = json.loads(answer.repairs)
    assert [p['summary'] for p in repairs['proposals']] == list(answer.summaries) and len(answer.summaries) == 2, \
        answer.repairs
    assert repairs['proposals'][0]['custom_ltl'] == {'env_props': ['door_open'], 'sys_liveness': ['door_open'],
                                                     'env_liveness': ['door_open']}
    assert all(p['verified'] for p in repairs['proposals'])
    unknown = client.call(ProposeRepairs.Request(system='atlass', goals=['look_down']), timeout_sec=60)
    assert unknown.error_code.value != 1 and 'atlass' in unknown.error_code.message


def test_no_fixes_when_the_budget_is_zero(ros, tmp_path):
    _, ours, _ = start_suite(ros, tmp_path, repair_time_budget=0.0)
    result = ours.run(make_goal(*WRONG_ORDER), timeout=120)
    assert result.error_name == 'SPEC_UNSYNTHESIZABLE' and 'Suggested fix' not in result.message
