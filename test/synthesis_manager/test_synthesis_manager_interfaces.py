"""Both action interfaces, with the payloads FlexBE WebUI revisions send, end to end in-process.

FlexBE WebUI 4.0.3 fills a BehaviorSynthesis goal field by field from
``{request: {name, system, goal, initial_condition, sm_outcomes}}``; newer revisions send one
payload with every field-name alias to CNU's FlexBESynthesis and keep the fields the type has.
/flexbe_synthesis offers CNU's own type when flexbe_synthesis_msgs is importable, else ours.
"""

from argparse import Namespace

import pytest

from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.ros.cnu_interface import load_flexbe_synthesis_interface
from synthesis_manager.suite import suite_node_factories
from synthesis_msgs.action import BehaviorSynthesis

pytestmark = pytest.mark.ros

FLEXBE_SYNTHESIS = load_flexbe_synthesis_interface()
SynthesisErrorCode = FLEXBE_SYNTHESIS.error_code_type

PAPER_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'pickup_object'])
# What WebUI 4.0.3 sends for a container "Container" with the default outcomes.
WEBUI_4_0_3_PAYLOAD = {'request': {'name': '/Container', 'system': 'system_wide',
                                   'goal': 'look_down, pickup_object', 'initial_condition': 'stand_prep',
                                   'sm_outcomes': ['finished', 'failed']}}
# What newer WebUI revisions send: every alias of every field, options as (empty) YAML.
WEBUI_ALIAS_PAYLOAD = {'request': {'name': '/Container', 'spec_name': '/Container',
                                   'system': 'system_wide', 'system_name': 'system_wide',
                                   'goal': 'look_down, pickup_object', 'goals': 'look_down, pickup_object',
                                   'initial_condition': 'stand_prep', 'initial_conditions': 'stand_prep',
                                   'sm_outcomes': ['finished', 'failed'], 'specification_file_name': ''},
                       'synthesis_options': ''}


def fill_field_by_field(message, values: dict):
    """Set nested values attribute by attribute, as WebUI 4.0.3's backend fills goals."""
    for key, value in values.items():
        if isinstance(value, dict):
            fill_field_by_field(getattr(message, key), value)
        else:
            setattr(message, key, value)
    return message


def fill_known_aliases(message, values: dict):
    """Keep the payload fields the message has; a text for a list field becomes a one-entry list."""
    fields = message.get_fields_and_field_types()
    for key, value in values.items():
        if key not in fields:
            continue
        if isinstance(value, dict):
            fill_known_aliases(getattr(message, key), value)
        elif fields[key].startswith('sequence') and isinstance(value, str):
            setattr(message, key, [value])
        else:
            setattr(message, key, value)
    return message


@pytest.fixture
def suite(ros, tmp_path):
    from rclpy.node import Node

    args = Namespace(config_dir='', byproducts_dir=str(tmp_path), backend='builtin', slugs_executable='slugs',
                     synthesis_timeout=60.0, service_timeout=2.0, default_system='')
    for factory in suite_node_factories(args):
        ros.add_node(factory)
    client_node = ros.add_node(Node, 'interfaces_test_client')
    clients = {name: SynthesisClient(client_node, name) for name in ('behavior_synthesis', 'flexbe_synthesis')}
    assert all(client.wait_for_server(timeout=10.0) for client in clients.values())
    return Namespace(byproducts=tmp_path, **clients)


def run_with_feedback(client, goal):
    feedback = []
    outcome = client.run(goal, feedback=lambda status, progress: feedback.append(status), timeout=120)
    return outcome, feedback


def machine(states):
    """The synthesized machine: each state's path, class and transitions."""
    return sorted((s['state_path'], s['state_class'], tuple(s['transitions'])) for s in states)


def test_webui_4_0_3_payload_names_the_behavior_by_its_container_path(suite):
    goal = fill_field_by_field(BehaviorSynthesis.Goal(), WEBUI_4_0_3_PAYLOAD)
    outcome, _ = run_with_feedback(suite.behavior_synthesis, goal)
    assert (outcome.goal_status, outcome.error_name) == ('SUCCEEDED', 'SUCCESS'), outcome.message
    classes = {s['state_class'] for s in outcome.states}
    assert {'TiltHeadState', ':BEHAVIOR', 'ChangeControlModeActionState'} <= classes
    # "/Container" names the behavior "Container"; its byproducts are named after it.
    assert sorted(p.name for p in suite.byproducts.glob('Container.*')) == [
        'Container.json', 'Container.slugsin', 'Container.structuredslugs']


def test_alias_filled_payload_against_flexbe_synthesis_gives_the_same_machine(suite):
    goal = fill_known_aliases(FLEXBE_SYNTHESIS.action_type.Goal(), WEBUI_ALIAS_PAYLOAD)
    assert list(goal.request.goals) == ['look_down, pickup_object'] and goal.synthesis_options == ''
    flexbe, _ = run_with_feedback(suite.flexbe_synthesis, goal)
    assert (flexbe.goal_status, flexbe.error_name) == ('SUCCEEDED', 'SUCCESS'), flexbe.message
    assert flexbe.error_code == SynthesisErrorCode.SUCCESS and flexbe.message == ''
    legacy, _ = run_with_feedback(suite.behavior_synthesis, make_goal(**PAPER_TASK))
    assert legacy.error_name == 'SUCCESS'
    assert machine(flexbe.states) == machine(legacy.states)
    assert flexbe.states == legacy.states


def test_synthesis_options_select_the_stop_point(suite):
    empty, _ = run_with_feedback(suite.flexbe_synthesis, make_flexbe_goal(**PAPER_TASK))
    assert empty.error_name == 'SUCCESS' and empty.states
    compiled, feedback = run_with_feedback(
        suite.flexbe_synthesis, make_flexbe_goal(option='ltl_compilation_only', **PAPER_TASK))
    assert compiled.error_name == 'SUCCESS' and compiled.states == []
    assert feedback[-1] == 'Compiled the LTL specification'
    goal = make_flexbe_goal(**PAPER_TASK)
    goal.synthesis_options = 'ltl_steps_only'
    steps, feedback = run_with_feedback(suite.flexbe_synthesis, goal)
    assert steps.error_name == 'SUCCESS' and steps.states == []
    assert feedback[-1].startswith('Synthesized an automaton')


def test_errors_reach_the_client_as_last_feedback_and_in_messages(suite):
    bad_goal = dict(system='system_wide', initial_conditions=['stand_prep'], goals=['fly_away'])
    legacy, legacy_feedback = run_with_feedback(suite.behavior_synthesis, make_goal(**bad_goal))
    assert (legacy.goal_status, legacy.error_name) == ('ABORTED', 'UNKNOWN_PROPOSITION')
    assert legacy_feedback[-1] == f'UNKNOWN_PROPOSITION: {legacy.message}' and 'fly_away' in legacy.message
    flexbe, flexbe_feedback = run_with_feedback(suite.flexbe_synthesis, make_flexbe_goal(**bad_goal))
    assert (flexbe.goal_status, flexbe.error_name) == ('ABORTED', 'SPEC_COMPILATION_FAILED')
    assert flexbe.message == legacy_feedback[-1] == flexbe_feedback[-1]

    bad_yaml = make_flexbe_goal(**PAPER_TASK)
    bad_yaml.synthesis_options = 'ltl_steps_only: [yes'
    invalid, feedback = run_with_feedback(suite.flexbe_synthesis, bad_yaml)
    assert (invalid.goal_status, invalid.error_name) == ('ABORTED', 'INVALID_REQUEST')
    assert invalid.message.startswith('INVALID_REQUEST: synthesis_options: not valid YAML')
    assert feedback == [invalid.message]

    unknown_system, _ = run_with_feedback(suite.flexbe_synthesis, make_flexbe_goal(
        system='r2d2', initial_conditions=['stand_prep'], goals=['look_down']))
    assert unknown_system.message.startswith('UNKNOWN_SYSTEM:') and 'r2d2' in unknown_system.message
    assert unknown_system.error_code == SynthesisErrorCode.NO_SYSTEM_CONFIG

    spec_file = make_flexbe_goal(**PAPER_TASK)
    spec_file.request.specification_file_name = 'mine.yaml'
    refused, _ = run_with_feedback(suite.flexbe_synthesis, spec_file)
    assert refused.error_name == 'INVALID_REQUEST' and 'mine.yaml' in refused.message
    assert run_with_feedback(suite.flexbe_synthesis, make_flexbe_goal(**PAPER_TASK))[0].error_name == 'SUCCESS'


def test_container_paths_become_distinct_safe_file_names(suite):
    for name in ('/Outer/Inner/Sub', 'a.b', 'a.c', '../escape'):
        outcome, _ = run_with_feedback(suite.flexbe_synthesis, make_flexbe_goal(name=name, **PAPER_TASK))
        assert outcome.error_name == 'SUCCESS', outcome.message
    assert sorted(p.name for p in suite.byproducts.glob('*.slugsin')) == [
        'Outer.Inner.Sub.slugsin', 'a-2eb.slugsin', 'a-2ec.slugsin', 'x--2e-2e.escape.slugsin']
    assert not list(suite.byproducts.parent.glob('escape*'))


def test_serve_default_system_answers_system_wide_requests(ros, tmp_path):
    from rclpy.node import Node

    from synthesis_manager.programs.cli import build_parser

    args = build_parser(only='serve').parse_args(
        ['serve', '--default-system', 'mobile_manipulator', '--byproducts-dir', str(tmp_path)])
    for factory in suite_node_factories(args):
        ros.add_node(factory)
    client = SynthesisClient(ros.add_node(Node, 'default_system_client'), 'flexbe_synthesis')
    assert client.wait_for_server(timeout=10.0)
    outcome = client.run(make_flexbe_goal('system_wide', ['parked'], ['dock']), timeout=120)
    assert outcome.error_name == 'SUCCESS', outcome.message
    atlas_only = client.run(make_flexbe_goal('', ['stand_prep'], ['look_down']), timeout=120)
    assert atlas_only.message.startswith('UNKNOWN_PROPOSITION:')
