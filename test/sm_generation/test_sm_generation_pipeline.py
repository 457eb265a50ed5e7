"""The whole chain on the paper's tasks: compile_task -> synthesize -> automaton -> FlexBE machine."""

import json

import pytest

from ltl_specification.compiler import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from sm_generation import generate_state_machine, validate_state_machine
from sm_generation.cli import main
from sm_generation.export import from_text, to_yaml
from sm_generation.traces import runs
from respec.robot import robot_system

_CACHE = {}


def synthesized(system, initial_conditions, goals, sm_outcomes=('finished', 'failed')):
    key = (system, initial_conditions, goals, sm_outcomes)
    if key not in _CACHE:
        spec = compile_task(robot_system(system), initial_conditions, goals, sm_outcomes=sm_outcomes)
        result = synthesize(spec)
        assert result.realizable, result.explanation
        _CACHE[key] = (spec, result.strategy, automaton_from_strategy(result.strategy, spec))
    return _CACHE[key]


def main_path(states):
    """Names of the states visited when every state reports success (its first outcome)."""
    top = {s.name: s for s in states if s.parent_path == '/' and s.state_class != ':OUTCOME'}
    path, current = [], states[0].initial_state_name
    while current in top and current not in path:
        path.append(current)
        current = top[current].transitions[0]
    return path, current


TASKS = [
    # (system, initial conditions, goals, expected states on the success path)
    ('atlas', 'stand_prep', 'look_down', ['stand', 'look_down']),
    ('atlas', 'stand_prep', 'look_down, pickup_object', None),
    ('atlas', 'stand_prep', 'pickup_object, grasp_object', None),
    ('atlas', 'stand_prep', 'footstep_execution', None),
    ('mobile_manipulator', 'parked', 'navigate', ['localize', 'driving', 'navigate']),
]


@pytest.mark.parametrize('system, initial_conditions, goals, expected', TASKS,
                         ids=[f'{t[0]}:{t[2]}' for t in TASKS])
def test_paper_tasks_give_valid_machines(system, initial_conditions, goals, expected):
    spec, _, automaton = synthesized(system, initial_conditions, goals)
    machine = generate_state_machine(automaton, robot_system(system), initial_conditions=[initial_conditions])
    states = machine.to_instantiations()
    assert validate_state_machine(states) == []
    assert states[0].outcomes == ['finished', 'failed']
    path, end = main_path(states)
    assert end == 'finished'
    goal_names = [g.strip() for g in goals.split(',')]
    # every goal is run, in the requested order, on the way to 'finished'
    assert [name for name in path if name in goal_names] == goal_names
    if expected is not None:
        assert path == expected
    reduced = generate_state_machine(automaton, robot_system(system), initial_conditions=[initial_conditions], reduce=True)
    assert validate_state_machine(reduced.to_instantiations()) == []
    assert runs(reduced, 8) == runs(machine, 8)


def test_two_behaviours_survive():
    _, _, automaton = synthesized('atlas', 'stand_prep', 'pickup_object, grasp_object')
    states = generate_state_machine(automaton, robot_system('atlas')).to_instantiations()
    behaviours = {s.behavior_class for s in states if s.state_class == ':BEHAVIOR'}
    assert behaviours == {'Pickup Object', 'Grasp Object'}


def test_pipeline_is_deterministic():
    first = to_yaml(generate_state_machine(synthesized('atlas', 'stand_prep', 'look_down, pickup_object')[2],
                                           robot_system('atlas')))
    spec = compile_task(robot_system('atlas'), 'stand_prep', 'look_down, pickup_object')
    again = automaton_from_strategy(synthesize(spec).strategy, spec)
    assert to_yaml(generate_state_machine(again, robot_system('atlas'))) == first


def test_retry_without_failed_outcome_and_reduction():
    """With sm_outcomes [finished] only, failures are retried; reduction folds the copies."""
    _, _, automaton = synthesized('atlas', 'stand_prep', 'look_down', ('finished',))
    machine = generate_state_machine(automaton, robot_system('atlas'))
    assert validate_state_machine(machine.to_instantiations()) == []
    assert machine.outcomes == ['finished']
    reduced = generate_state_machine(automaton, robot_system('atlas'), reduce=True)
    top = {s.name: dict(zip(s.outcomes, s.transitions)) for s in reduced.states}
    assert top == {'stand': {'changed': 'look_down', 'failed': 'stand'},
                   'look_down': {'done': 'finished', 'failed': 'look_down'}}
    assert runs(reduced, 8) == runs(machine, 8)


def test_cli_reads_a_slugs_strategy_with_its_spec(tmp_path):
    spec, strategy, automaton = synthesized('atlas', 'stand_prep', 'look_down, pickup_object')
    (tmp_path / 'task.structuredslugs').write_text(spec.to_structuredslugs())
    (tmp_path / 'task.json').write_text(json.dumps(strategy))
    out = tmp_path / 'task.yaml'
    assert main(['--system', 'atlas', '--automaton', str(tmp_path / 'task.json'),
                 '--spec', str(tmp_path / 'task.structuredslugs'), '-o', str(out)]) == 0
    assert from_text(out.read_text()) == generate_state_machine(automaton, robot_system('atlas')).to_instantiations()
