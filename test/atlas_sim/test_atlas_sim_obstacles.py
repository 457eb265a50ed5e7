"""Physics the trace check believes (issue 35): the table collides, walks go around it or fail
naming it, and the robot's body in furniture (or a fall) is a violation of the run.

The 12-goal ATLAS task of the GUI once walked the robot through the table while the check
said "ok"; here it walks around the table, and a robot walking blind (``scene.look_ahead``
false) runs into it and the check fails the run.
"""

import dataclasses

import pytest

from atlas_sim.closed_loop import run_and_check
from atlas_sim.executive.trace_check import Trace, TraceStep, check_trace
from atlas_sim.simulated_robot import SimulatedRobot
from atlas_sim.simulator import AtlasSimulator
from atlas_sim.simulator.factory import make_simulator
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot import robot_system
from sm_generation import generate_state_machine

pytestmark = pytest.mark.mujoco

ATLAS = robot_system('atlas')

TWELVE_GOALS = ['look_down', 'approach_object', 'pregrasp', 'grasp_object', 'pickup_object',
                'footstep_execution', 'object_template', 'pregrasp_pose', 'footstep_plan', 'target_pose',
                'pregrasp_plan', 'footstep_goal']
TABLE_FRONT_X = 0.42  # the table top's near edge (models/humanoid.xml: body at 0.62, half size 0.2)
TABLE_Y = (-0.33, 0.17)  # its sides


def with_scene(simulator, **scene):
    """A fresh simulator of the same config with ``simulation.scene`` fields replaced."""
    config = simulator.config
    settings = dataclasses.replace(config.simulation, scene=dataclasses.replace(config.simulation.scene, **scene))
    return AtlasSimulator(dataclasses.replace(config, simulation=settings))


@pytest.fixture(scope='module')
def twelve_goal_task():
    spec = compile_task(ATLAS, ['stand_prep'], TWELVE_GOALS)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    return spec, generate_state_machine(automaton, ATLAS, initial_conditions=['stand_prep'])


def run_twelve_goals(task, simulator):
    spec, states = task
    path = []
    run = run_and_check(states, SimulatedRobot(simulator), simulator, ATLAS, spec, TWELVE_GOALS,
                        on_progress=lambda steps, frames: path.append(simulator.physics.pelvis_position()[:2]))
    return run, path


# --- the 12-goal run ---------------------------------------------------------------------------

def test_the_twelve_goal_run_walks_around_the_table_and_the_check_passes_it(twelve_goal_task):
    run, path = run_twelve_goals(twelve_goal_task, make_simulator(ATLAS, initial_conditions=['stand_prep']))
    assert run.result.outcome == 'finished'
    assert run.check.ok, run.check.summary()
    assert run.result.trace.incidents == [] and not run.result.fallen
    # the pelvis never stood over the table: once past its near edge it is beside it
    beside = [(x, y) for x, y in path if x > TABLE_FRONT_X]
    assert beside and all(y > TABLE_Y[1] + 0.2 or y < TABLE_Y[0] - 0.2 for x, y in beside)


def test_the_twelve_goal_run_of_a_blind_robot_hits_the_table_and_the_check_fails_it(twelve_goal_task):
    blind = with_scene(make_simulator(ATLAS, initial_conditions=['stand_prep']), look_ahead=False)
    run, _ = run_twelve_goals(twelve_goal_task, blind)
    contacts = [v for v in run.check.violations if v.kind == 'contact']
    assert not run.check.ok and contacts, run.check.summary()
    assert all('table' in v.message for v in contacts)
    walking = {step.index for step in run.result.trace.steps if 'footstep_execution' in step.capabilities}
    assert {v.step for v in contacts} <= walking  # reported at the walk that ran into it
    assert 'contact' in run.check.summary()


# --- walks and the table -----------------------------------------------------------------------

def test_a_walk_whose_way_is_blocked_on_both_sides_fails_naming_the_table():
    simulator = with_scene(make_simulator(ATLAS, initial_conditions=['stand']), clearance=1.5)
    x_before = simulator.snapshot()['base_xy'][0]
    result = simulator.execute('walk')
    assert result.outcome == 'failed'
    assert 'blocked by table' in result.reason and 'no detour' in result.reason
    assert simulator.mode == 'stand' and simulator.snapshot()['base_xy'][0] == pytest.approx(x_before, abs=0.01)


def test_a_short_walk_with_room_ahead_goes_straight():
    simulator = make_simulator(ATLAS, initial_conditions=['stand'])
    simulator.execute('object_template')
    assert simulator.execute('approach_object').completed
    x, y = simulator.snapshot()['base_xy']
    assert x == pytest.approx(0.2, abs=0.05) and abs(y) < 0.05 and simulator.incidents == []


def test_walking_blind_into_the_table_is_an_incident_naming_the_part_and_the_table():
    simulator = with_scene(make_simulator(ATLAS, initial_conditions=['stand']), look_ahead=False)
    simulator.execute('walk')
    contacts = [i for i in simulator.incidents if i.kind == 'contact']
    assert contacts and {i.obstacle for i in contacts} == {'table'}
    assert all(i.part not in ('left_hand', 'right_hand', 'left_finger', 'right_finger') for i in contacts)
    assert all(f'{i.part} ran into table' in i.message and 'walk' in i.message for i in contacts)


# --- the check on constructed traces ----------------------------------------------------------

@pytest.fixture(scope='module')
def walk_spec():
    return compile_task(ATLAS, ['stand_prep'], ['walk'], sm_outcomes=['finished', 'failed'])


def walk_trace(incidents=()):
    """stand_prep -> stand -> walk -> finished, as the executor records it, with ``incidents``."""
    stand = TraceStep(0, '/stand', 'ChangeControlModeActionState', ['stand_a'], ['stand'], 0.0, 1.5,
                      'stand_prep', 'stand', ['stand_prep_c'], ['stand_c'],
                      [{'capability': 'stand', 'outcome': 'completed', 'reason': '', 'time': 1.5,
                        'abandoned': False}], 'changed', 'walk')
    walk = TraceStep(1, '/walk', 'ChangeControlModeActionState', ['walk_a'], ['walk'], 1.5, 6.0,
                     'stand', 'walk', ['stand_c'], ['walk_c'],
                     [{'capability': 'walk', 'outcome': 'completed', 'reason': '', 'time': 6.0,
                       'abandoned': False}], 'changed', 'finished')
    return Trace([stand, walk], 'finished', incidents=list(incidents))


def test_a_run_without_incidents_passes(walk_spec):
    assert check_trace(walk_trace(), walk_spec).ok


def test_a_contact_is_a_violation_at_the_step_that_ran_then(walk_spec):
    contact = {'kind': 'contact', 'time': 4.2, 'message': "the robot's left_thigh ran into table (during walk)",
               'part': 'left_thigh', 'obstacle': 'table'}
    report = check_trace(walk_trace([contact]), walk_spec)
    assert not report.ok
    [violation] = report.violations
    assert (violation.kind, violation.step, violation.transition) == ('contact', 1, '/walk')
    assert violation.message == contact['message'] and violation.formulas == []
    assert 'contact at step 1 (/walk)' in report.summary()


def test_a_fall_is_a_violation_even_when_the_outcomes_are_right(walk_spec):
    fall = {'kind': 'fall', 'time': 0.5, 'message': 'robot fell (pelvis height 0.40 m, torso tilt 60 deg)'}
    report = check_trace(walk_trace([fall]), walk_spec)
    assert [(v.kind, v.step) for v in report.violations] == [('fall', 0)]


def test_incidents_survive_the_json_of_a_trace(walk_spec):
    contact = {'kind': 'contact', 'time': 2.0, 'message': 'm', 'part': 'right_shin', 'obstacle': 'table'}
    again = Trace.from_dict(walk_trace([contact]).to_dict())
    assert again.incidents == [contact]
    assert check_trace(again, walk_spec).to_dict() == check_trace(walk_trace([contact]), walk_spec).to_dict()
