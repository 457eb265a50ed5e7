"""Initial conditions detected at runtime: the robot state -> 𝓘 mapping and the status line (no ROS)."""

import pytest

from ltl_specification.compiler import compile_task
from ltl_specification.errors import InvalidInitialConditionsError
from ltl_specification.initial_conditions import (CURRENT, asks_for_robot_state, detected_status,
                                                  initial_conditions_from_robot_state,
                                                  initial_conditions_in_status)
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from sm_generation import generate_state_machine
from respec.robot import robot_system

# Where the paper's first task (stand_prep -> look_down, pickup_object) leaves ATLAS.
AFTER_PICKUP = dict(mode='manipulate', completed_actions=['look_down', 'object_template', 'pickup_object'])


@pytest.mark.parametrize('names, expected', [([], True), ([CURRENT], True), (['stand'], False),
                                             (['manipulate', 'object_template'], False)])
def test_no_initial_conditions_or_current_ask_for_the_robot_state(names, expected):
    assert asks_for_robot_state(names) is expected


def test_current_cannot_be_combined_with_named_initial_conditions():
    with pytest.raises(InvalidInitialConditionsError) as raised:
        asks_for_robot_state(['stand', CURRENT, 'look_down'])
    assert raised.value.item == 'stand' and raised.value.code == 'INVALID_INITIAL_CONDITIONS'
    assert "'stand', 'look_down'" in str(raised.value)


def test_robot_state_gives_its_mode_then_its_completed_actions():
    assert initial_conditions_from_robot_state(**AFTER_PICKUP) == [
        'manipulate', 'look_down', 'object_template', 'pickup_object']
    assert initial_conditions_from_robot_state('stand', ['look_down', '', 'look_down']) == ['stand', 'look_down']
    assert initial_conditions_from_robot_state('stand_prep', []) == ['stand_prep']


def test_a_robot_state_without_control_mode_is_an_error_naming_its_source():
    with pytest.raises(InvalidInitialConditionsError) as raised:
        initial_conditions_from_robot_state('', ['look_down'], source='atlas_sim/state')
    assert raised.value.item == 'atlas_sim/state' and 'atlas_sim/state' in str(raised.value)


def test_status_line_round_trip():
    status = detected_status(['manipulate', 'pickup_object'], 'atlas_sim/state')
    assert status == 'Initial conditions from atlas_sim/state: manipulate, pickup_object'
    assert initial_conditions_in_status(status) == ('atlas_sim/state', ['manipulate', 'pickup_object'])
    assert initial_conditions_in_status('Compiling the LTL specification') is None


def test_paper_second_demo_from_the_state_after_the_first_task():
    """Fig. 7b: from 𝓘 = {manipulate} (plus what the first task completed) to footstep_execution."""
    initial_conditions = initial_conditions_from_robot_state(**AFTER_PICKUP)
    spec = compile_task(robot_system('atlas'), initial_conditions, ['footstep_execution'])
    env_init = spec.to_text_sections()['env_init']
    assert 'manipulate_c' in env_init and '!stand_c' in env_init
    result = synthesize(spec)
    assert result.realizable
    machine = generate_state_machine(automaton_from_strategy(result.strategy, spec), robot_system('atlas'),
                                     initial_conditions=initial_conditions)
    top = {s.name: s for s in machine.states}
    path, current = [], machine.initial_state_name
    while current in top and current not in path:  # every state succeeding: its first outcome
        path.append(current)
        current = top[current].transitions[0]
    assert current == 'finished'
    # nothing the robot already did is redone; it leaves manipulate for stand before walking
    assert sorted(path) == sorted(['target_pose', 'footstep_goal', 'footstep_plan', 'stand', 'footstep_execution'])
    order = path.index
    assert order('target_pose') < order('footstep_goal') < order('footstep_plan') < order('footstep_execution')
    assert order('stand') < order('footstep_execution')
