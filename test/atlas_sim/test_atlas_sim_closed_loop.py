"""Closed loop without ROS: task -> spec -> controller -> FlexBE machine -> simulated ATLAS -> trace check.

Synthesis goes through the ROS-free cores (compile_task -> synthesize -> automaton_from_strategy
-> generate_state_machine); test_atlas_sim_closed_loop_ros.py runs the same loop over ROS.
"""

import json
import math

import pytest

from atlas_sim.executive.executor import execute_state_machine
from atlas_sim.executive.trace_check import check_trace
from atlas_sim.simulated_robot import SimulatedRobot
from atlas_sim.simulator.factory import make_simulator, parse_faults
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from sm_generation import generate_state_machine, validate_state_machine
from respec.robot import robot_system

pytestmark = pytest.mark.mujoco

STAND_HEIGHT_RANGE = (0.6, 1.1)  # pelvis height (m): crouched stand_prep is ~0.67, standing ~0.85


def synthesize_machine(initial_conditions, goals, sm_outcomes=('finished', 'failed')):
    spec = compile_task(robot_system('atlas'), initial_conditions, goals, sm_outcomes=sm_outcomes)
    result = synthesize(spec)
    assert result.realizable, result.explanation
    automaton = automaton_from_strategy(result.strategy, spec)
    machine = generate_state_machine(automaton, robot_system('atlas'), initial_conditions=initial_conditions)
    assert validate_state_machine(machine.to_instantiations()) == []
    return spec, machine


def run_task(initial_conditions, goals, sm_outcomes=('finished', 'failed'), **fault_lists):
    """Synthesize, execute on a fresh simulator, check the trace and the robot's health."""
    spec, states = synthesize_machine(initial_conditions, goals, sm_outcomes)
    simulator = make_simulator(robot_system('atlas'), initial_conditions=initial_conditions,
                               faults=parse_faults(**fault_lists))
    run = execute_state_machine(states, SimulatedRobot(simulator), robot_system('atlas'))
    report = check_trace(run.trace, spec, goals=goals)
    assert report.ok, report.summary()
    assert not run.fallen and not simulator.has_fallen()
    low, high = STAND_HEIGHT_RANGE
    assert low < run.min_pelvis_height and low < simulator.snapshot()['pelvis_height'] < high
    return run, report, simulator


def test_look_down_then_pickup_object_finishes():
    run, report, simulator = run_task(['stand_prep'], ['look_down', 'pickup_object'])
    assert run.outcome == 'finished'
    assert report.goals_completed_at['look_down'] < report.goals_completed_at['pickup_object']
    snapshot = simulator.snapshot()
    assert snapshot['mode'] == 'manipulate' and snapshot['holding_object']
    assert math.degrees(snapshot['head_tilt']) == pytest.approx(45, abs=8)
    # the object left the table (top at 0.68 m) and hangs just below the hands
    hands = (simulator.physics.body_position('left_hand') + simulator.physics.body_position('right_hand')) / 2
    assert simulator.physics.object_position()[2] > 0.85
    assert simulator.physics.object_position() == pytest.approx(hands + [0, 0, -0.12], abs=0.01)


def test_the_object_waits_on_the_table_until_picked_up():
    _, _, simulator = run_task(['stand_prep'], ['look_down', 'pickup_object'], fail=['pickup_object'])
    assert simulator.physics.object_position() == pytest.approx([0.55, -0.08, 0.72])


def test_pickup_object_failing_ends_in_failed():
    run, report, simulator = run_task(['stand_prep'], ['look_down', 'pickup_object'], fail=['pickup_object'])
    assert run.outcome == 'failed'
    last = run.trace.steps[-1]
    assert last.state == '/pickup_object' and last.results[0]['outcome'] == 'failed'
    # look_down completed (its step depends on which valid strategy the synthesizer picks).
    assert report.goals_completed_at['look_down'] is not None
    assert report.goals_completed_at['pickup_object'] is None
    assert not simulator.snapshot()['holding_object']


def test_footstep_execution_from_manipulate_finishes():
    run, report, simulator = run_task(['manipulate'], ['footstep_execution'])
    assert run.outcome == 'finished'
    assert run.trace.steps[0].mode_at_entry == 'manipulate'
    assert 'stand' in [s.state.lstrip('/') for s in run.trace.steps]  # footsteps need stand
    assert simulator.snapshot()['base_xy'][0] > 0.25  # three steps of 0.15 m forward


def test_walk_finishes():
    run, report, simulator = run_task(['stand_prep'], ['walk'])
    assert run.outcome == 'finished'
    assert [s.state for s in run.trace.steps] == ['/stand', '/walk']
    assert simulator.mode == 'walk' and simulator.snapshot()['base_xy'][0] > 0.3


def test_with_finished_only_a_twice_failing_action_is_retried_and_the_run_finishes():
    run, report, simulator = run_task(['stand_prep'], ['look_down', 'pickup_object'], sm_outcomes=['finished'],
                                      fail_first=['pickup_object:2'])
    assert run.outcome == 'finished'
    attempts = [r['outcome'] for s in run.trace.steps for r in s.results if r['capability'] == 'pickup_object']
    assert attempts == ['failed', 'failed', 'completed']
    assert simulator.faults.attempts('pickup_object') == 3
    assert simulator.snapshot()['holding_object']


def test_the_same_task_gives_the_same_trace():
    first, _, _ = run_task(['stand_prep'], ['walk'])
    second, _, _ = run_task(['stand_prep'], ['walk'])
    assert json.dumps(first.to_dict(), sort_keys=True) == json.dumps(second.to_dict(), sort_keys=True)
