"""Loading and validating the abstraction: section of system configuration files."""

import pytest

from respec.robot import robot_system
from respec.robot.abstraction import AbstractionConfigError, abstraction_from_dict
from respec.robot.files import SystemNotFoundError


def section(**overrides):
    base = {
        'outcomes': ['completed', 'failed'],
        'initial_mode': 'parked',
        'control_modes': {'parked': ['driving'], 'driving': ['parked']},
        'actions': {'navigate': ['localize', 'driving'], 'localize': []},
        'sensors': ['bump'],
    }
    base.update(overrides)
    return base


def rejected(data) -> AbstractionConfigError:
    with pytest.raises(AbstractionConfigError) as caught:
        abstraction_from_dict(data, 'robot')
    return caught.value


def test_atlas_abstraction_loads_in_file_order():
    atlas = robot_system('atlas').abstraction
    assert list(atlas.control_modes) == ['stand_prep', 'stand', 'manipulate', 'step', 'walk']
    assert atlas.control_modes['stand'] == ('manipulate', 'step', 'walk')
    assert atlas.actions['pickup_object'] == ('object_template', 'manipulate')
    assert atlas.actions['look_down'] == ('stand',)
    assert atlas.outcomes == ('completed', 'failed')
    assert atlas.success_outcome == 'completed' and atlas.failure_outcomes == ('failed',)
    assert atlas.sensors == ('obj_detected',)
    assert atlas.initial_mode == 'stand_prep'
    assert atlas.kind_of('walk') == 'control_mode' and atlas.kind_of('look_down') == 'action'
    assert atlas.kind_of('fly') is None


def test_mobile_manipulator_abstraction_loads():
    robot = robot_system('mobile_manipulator').abstraction
    assert list(robot.control_modes) == ['parked', 'driving', 'manipulating']
    assert robot.initial_mode == 'parked'
    assert robot.actions['grasp'] == ('plan_grasp', 'manipulating')


def test_listed_self_loops_are_dropped_because_implied():
    robot = abstraction_from_dict(section(control_modes={'parked': ['parked', 'driving'], 'driving': []}))
    assert robot.control_modes == {'parked': ('driving',), 'driving': ()}


def test_defaults_outcomes_and_optional_sections():
    robot = abstraction_from_dict({'actions': {'beep': []}})
    assert robot.outcomes == ('completed', 'failed')
    assert robot.control_modes == {} and robot.sensors == () and robot.initial_mode is None


def test_unknown_system():
    with pytest.raises(SystemNotFoundError) as caught:
        robot_system('no_such_robot')
    assert caught.value.item == 'no_such_robot'


def test_unknown_precondition():
    error = rejected(section(actions={'navigate': ['localise']}))
    assert error.item == 'localise' and 'unknown precondition' in str(error)


def test_cycle_in_preconditions_names_the_cycle():
    error = rejected(section(actions={'a': ['b'], 'b': ['c'], 'c': ['a']}))
    assert error.item == 'a'
    assert 'a -> b -> c -> a' in str(error)


def test_action_that_is_its_own_precondition_is_a_cycle():
    assert rejected(section(actions={'a': ['a']})).item == 'a'


def test_adjacency_naming_unknown_mode():
    error = rejected(section(control_modes={'parked': ['flying']}))
    assert error.item == 'flying' and 'not a control mode' in str(error)


def test_action_and_mode_with_the_same_name():
    error = rejected(section(actions={'driving': [], 'navigate': []}))
    assert error.item == 'driving' and 'both an action and a control mode' in str(error)


def test_outcomes_with_equal_first_letters():
    error = rejected(section(outcomes=['completed', 'failed', 'crashed']))
    assert error.item == 'crashed' and 'same first letter' in str(error)


@pytest.mark.parametrize('outcome', ['aborted', 'missed'])
def test_outcome_letters_reserved_for_activation_and_memory(outcome):
    assert rejected(section(outcomes=['completed', outcome])).item == outcome


def test_empty_outcomes():
    assert rejected(section(outcomes=[])).item == 'outcomes'


@pytest.mark.parametrize('data, item', [
    ('not a mapping', 'abstraction'),
    (section(actions=['navigate']), 'actions'),
    (section(control_modes={'parked': 'driving'}), 'control_modes.parked'),
    (section(sensors='bump'), 'sensors'),
    (section(outcomes=['completed', 3]), '3'),
    (section(actions={'navigate': [], 'bad name': []}), 'bad name'),
    (section(colour='red'), 'colour'),
])
def test_wrong_types_and_keys(data, item):
    assert rejected(data).item == item


def test_initial_mode_must_be_a_mode():
    assert rejected(section(initial_mode='localize')).item == 'localize'


def test_generated_proposition_clash_with_sensor():
    error = rejected(section(sensors=['navigate_c']))
    assert error.item == 'navigate_c' and 'both' in str(error)


def test_sensor_named_like_sm_outcome():
    assert rejected(section(sensors=['finished'])).item == 'finished'


def test_duplicate_sensor():
    assert rejected(section(sensors=['bump', 'bump'])).item == 'bump'
