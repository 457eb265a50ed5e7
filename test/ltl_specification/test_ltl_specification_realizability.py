"""Compiled specifications are realizable under robotics semantics, and not vacuously.

Realizability is decided by ltl_synthesizer.synthesize (slugs' --sysInitRoboticsSemantics:
every state allowed by both init sections must be winning) and, for specifications small
enough, cross-checked with the independent explicit-state solver test/gr1_oracle.py.
"""

import dataclasses

import pytest
import yaml

import gr1_oracle
from ltl_specification import compile_task
from ltl_synthesizer import is_realizable, synthesize
from ltl_specification import activation_outcomes as ao
from respec.ltl import FALSE
from respec.robot import robot_system

TASKS = {
    'paper demo 1: look_down, pickup_object': ('atlas', ['stand_prep'], ['look_down', 'pickup_object']),
    'paper demo 2: footstep_execution': ('atlas', ['manipulate'], ['footstep_execution']),
    'walk': ('atlas', ['stand_prep'], ['walk']),
    'step': ('atlas', ['stand_prep'], ['step']),
    'pickup then walk': ('atlas', ['stand_prep'], ['pickup_object', 'walk']),
    'mobile manipulator: grasp, place': ('mobile_manipulator', [], ['grasp', 'place']),
}


def assert_realizable(spec):
    result = synthesize(spec, robotics_semantics=True)
    assert result.realizable, result.explanation
    assert result.strategy['nodes']
    return result


@pytest.mark.parametrize('name', list(TASKS))
def test_strict_order_tasks_are_realizable(name):
    system, initial, goals = TASKS[name]
    assert_realizable(compile_task(robot_system(system), initial, goals))


@pytest.mark.parametrize('name', ['paper demo 1: look_down, pickup_object', 'pickup then walk'])
def test_unordered_goals_are_realizable(name):
    system, initial, goals = TASKS[name]
    assert_realizable(compile_task(robot_system(system), initial, goals, strict_order=False))


@pytest.mark.parametrize('name', ['paper demo 1: look_down, pickup_object', 'paper demo 2: footstep_execution',
                                  'walk'])
def test_retry_after_failure_is_realizable(name):
    system, initial, goals = TASKS[name]
    assert_realizable(compile_task(robot_system(system), initial, goals, sm_outcomes=['finished']))


def test_mobile_manipulator_retry_is_realizable():
    assert_realizable(compile_task(robot_system('mobile_manipulator'), [], ['navigate', 'detect_object'],
                                   sm_outcomes=['finished']))


def without_success(spec):
    """The same specification with an impossible system goal: realizable only vacuously."""
    return dataclasses.replace(spec, sys_liveness=[FALSE])


@pytest.mark.parametrize('sm_outcomes', [['finished', 'failed'], ['finished']])
def test_environment_assumptions_cannot_be_forced_false(sm_outcomes):
    # If the system could make the environment violate an assumption, it would win even a
    # goal that never holds. It must not.
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'], sm_outcomes=sm_outcomes)
    assert not is_realizable(without_success(spec))


def original_retry_encoding(spec):
    """Retry as the original encoded it: deactivate after any outcome, fairness on any outcome."""
    p = spec.provenance.pertinence
    original = dataclasses.replace(spec)
    original.sys_trans = spec.sys_trans + [f for item in (*p.modes, *p.actions)
                                           for f in ao.deactivation_after_outcome(item, ['failed'])]
    original.env_liveness = ([ao.mode_fairness(p.modes, ['completed', 'failed'])]
                             + [ao.action_fairness(a, ['completed', 'failed']) for a in p.actions])
    return original


def test_the_original_retry_encoding_is_unrealizable_and_ours_is_not():
    spec = compile_task(robot_system('atlas'), ['manipulate'], ['footstep_execution'], sm_outcomes=['finished'])
    assert synthesize(spec).realizable
    assert not is_realizable(original_retry_encoding(spec))


# --- cross-check with the independent explicit-state oracle (small specifications) ---------------

@pytest.fixture
def beeper(tmp_path):
    """A one-mode, two-action system: small enough (at most 10 propositions) for the oracle."""
    (tmp_path / 'beeper.yaml').write_text(yaml.safe_dump({'abstraction': {
        'control_modes': {'on': []}, 'initial_mode': 'on',
        'actions': {'beep': ['on'], 'blink': []}}}))
    return tmp_path


@pytest.mark.parametrize('sm_outcomes, goals', [
    (['finished', 'failed'], ['beep']),
    (['finished'], ['beep']),
    (['finished', 'failed'], ['blink']),
])
def test_oracle_agrees_small_system(beeper, sm_outcomes, goals):
    spec = compile_task(robot_system('beeper', beeper), [], goals, sm_outcomes=sm_outcomes)
    assert len(spec.propositions()) <= 10
    assert gr1_oracle.solve(spec, robotics_semantics=True)
    assert not gr1_oracle.solve(without_success(spec), robotics_semantics=True)


def test_oracle_agrees_original_retry_is_unrealizable(beeper):
    spec = compile_task(robot_system('beeper', beeper), [], ['beep'], sm_outcomes=['finished'])
    assert gr1_oracle.solve(spec)
    assert not gr1_oracle.solve(original_retry_encoding(spec))


def test_oracle_agrees_walk_with_retry():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['walk'], sm_outcomes=['finished'])
    assert len(spec.propositions()) == 11
    assert gr1_oracle.solve(spec, robotics_semantics=True)
