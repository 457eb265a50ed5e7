"""validate_state_machine finds each kind of inconsistency."""

import copy
from pathlib import Path

import pytest

from sm_generation import OutcomeCondition, StateInstantiation, generate_state_machine, load_automaton
from sm_generation import validate_state_machine
from respec.robot import robot_system

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'


@pytest.fixture(scope='module')
def concurrent():
    return generate_state_machine(load_automaton(AUTOMATA / 'concurrent.yaml'), robot_system('atlas')).to_instantiations()


def broken(states, path, **changes):
    states = copy.deepcopy(states)
    entry = next(s for s in states if s.state_path == path)
    for name, value in changes.items():
        setattr(entry, name, value)
    return validate_state_machine(states)


def test_generated_machine_is_valid(concurrent):
    assert validate_state_machine(concurrent) == []


def test_empty_list():
    assert validate_state_machine([]) == ['the state machine is empty']


@pytest.mark.parametrize('path, changes, expected', [
    ('/pregrasp_pose', {'transitions': ['finished', 'nowhere', 'failed']}, "transition 'nowhere'"),
    ('/pregrasp_pose', {'transitions': ['finished']}, '3 outcomes but 1 transitions'),
    ('/pregrasp_pose', {'autonomy': [0]}, '3 outcomes but 1 autonomy levels'),
    ('/pregrasp_pose', {'autonomy': [0, 0, 300]}, 'autonomy must be a list of int8'),
    ('/pregrasp_pose', {'position': [1.0]}, 'position must be two numbers'),
    ('/pregrasp_pose', {'outcomes': 'done'}, 'outcomes must be a list of strings'),
    ('/pregrasp_pose', {'parameter_names': ['x', 'y']}, 'parameter_names and parameter_values'),
    ('/pregrasp_pose', {'userdata_keys': ['x']}, 'userdata_keys and userdata_remapping'),
    ('/pregrasp_pose', {'state_class': ':BEHAVIOR'}, ':BEHAVIOR without behavior_class'),
    ('/pregrasp_pose', {'state_class': ''}, 'empty state_class'),
    ('/', {'initial_state_name': 'nowhere'}, "initial_state_name 'nowhere'"),
    ('/', {'initial_state_name': ''}, 'without initial_state_name'),
    ('/', {'state_path': '/root'}, 'root container'),
    ('/object_template_and_stand/stand', {'transitions': ['object_template', 'stand_f']},
     "transition 'object_template'"),
    ('/object_template_and_stand', {'cond_outcome': ['stand_c']}, 'differ in length'),
    ('/object_template_and_stand', {'cond_transition': [OutcomeCondition(['ghost'], ['done'])] * 9},
     "unknown inner state 'ghost'"),
    ('/object_template_and_stand', {'cond_transition': [OutcomeCondition(['stand'], ['exploded'])] * 9},
     "has no outcome 'exploded'"),
    ('/object_template_and_stand', {'cond_transition': [OutcomeCondition([], [])] * 9}, 'empty or uneven'),
    ('/finished', {'state_path': '/done'}, 'not an outcome of /'),
])
def test_each_problem_is_reported(concurrent, path, changes, expected):
    problems = broken(concurrent, path, **changes)
    assert any(expected in p for p in problems), problems


def test_duplicate_paths_and_orphans(concurrent):
    states = copy.deepcopy(concurrent)
    states.append(copy.deepcopy(states[2]))
    assert any('duplicate state_path' in p for p in validate_state_machine(states))
    orphan = StateInstantiation(state_path='/nowhere/x', state_class='LogState')
    assert any("parent '/nowhere'" in p for p in validate_state_machine(concurrent + [orphan]))


def test_unreachable_state(concurrent):
    lonely = StateInstantiation(state_path='/lonely', state_class='LogState', outcomes=['done'],
                                transitions=['finished'], autonomy=[0])
    assert any('/lonely: unreachable' in p for p in validate_state_machine(concurrent + [lonely]))


def test_container_outcome_without_condition(concurrent):
    problems = broken(concurrent, '/object_template_and_stand',
                      outcomes=['object_template_c__stand_c', 'object_template_f__stand_c', 'object_template_f',
                                'stand_c', 'stand_f', 'extra'],
                      transitions=['pregrasp_pose', 'failed', 'failed', 'object_template', 'failed', 'failed'],
                      autonomy=[0] * 6)
    assert any("'extra' has no condition" in p for p in problems)


def test_not_a_state_instantiation():
    assert validate_state_machine([{'state_path': '/'}]) == ['entry #0: not a StateInstantiation: dict']
