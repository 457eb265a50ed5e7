"""The simulated ATLAS checks the data that reaches a request, as the real robot would.

FlexBE's InputState writes the operator's template id to userdata and the states acting on
the object pass it on; the robot never sees ``object_template`` "complete".
"""

import copy

import pytest
import yaml

from atlas_sim.simulator.atlas_simulator import AtlasSimulator
from atlas_sim.simulator.config import DEFAULT_CONFIG, SimulationConfigError, SystemConfig

pytestmark = pytest.mark.mujoco


def atlas_document():
    with open(DEFAULT_CONFIG, encoding='utf-8') as stream:
        return yaml.safe_load(stream)


@pytest.fixture(scope='module')
def document():
    return atlas_document()


def simulator(document, **simulation_changes):
    document = copy.deepcopy(document)
    document['simulation']['initial_mode'] = 'manipulate'
    document['simulation'].update(simulation_changes)
    return AtlasSimulator(SystemConfig.from_dict(document))


def test_pickup_with_the_operators_template_id_needs_no_object_template_run(document):
    sim = simulator(document)
    request = sim.start('pickup_object', data={'template_id': 1})
    sim.run_until_idle()
    assert request.result.completed, request.result.reason
    assert sim.snapshot()['holding_object']


@pytest.mark.parametrize('value, words', [
    (7, 'template_id 7 names no object of the scene (known template ids: 1)'),
    ('box', "template_id 'box' is not an object template id"),
    (None, 'template_id None is not an object template id'),
    (True, 'template_id True is not an object template id'),
])
def test_a_wrong_template_id_fails_with_the_reason(document, value, words):
    request = simulator(document).start('pickup_object', data={'template_id': value})
    assert request.result is not None and not request.result.completed
    assert words in request.result.reason


def test_a_request_with_data_but_no_template_id_says_what_is_missing(document):
    request = simulator(document).start('pickup_object', data={})
    assert request.result.reason == ('pickup_object needs template_id (what object_template provides); '
                                     'the request carries none')


def test_physical_preconditions_still_hold_with_data(document):
    request = simulator(document, initial_mode='stand').start('pickup_object', data={'template_id': 1})
    assert request.result.reason == 'preconditions of pickup_object not met: manipulate'


def test_an_object_out_of_reach_cannot_be_picked_up(document):
    request = simulator(document, scene={'objects': {1: 'pickup_object'}, 'reach': 0.2}).start(
        'pickup_object', data={'template_id': 1})
    assert request.result is not None
    assert 'object 1 (pickup_object) is 0.' in request.result.reason
    assert 'beyond reach (0.2 m)' in request.result.reason


def test_without_data_the_simulators_own_operator_answers(document):
    sim = simulator(document)
    refused = sim.start('pickup_object')
    assert refused.result.reason == 'preconditions of pickup_object not met: object_template'
    assert sim.execute('object_template').completed
    assert sim.answers == {'template_id': 1}
    assert sim.execute('pickup_object').completed


def test_footstep_goal_takes_a_pose(document):
    sim = simulator(document, initial_mode='stand')
    bad = sim.start('footstep_goal', data={'target_pose': [1.0, 'x', 0.0]})
    assert "target_pose [1.0, 'x', 0.0] is not a pose" in bad.result.reason
    good = sim.start('footstep_goal', data={'target_pose': [0.6, 0.0, 0.0]})
    sim.run_until_idle()
    assert good.result.completed


def test_long_data_is_quoted_short(document):
    request = simulator(document).start('pickup_object', data={'template_id': 'x' * 10_000})
    assert len(request.result.reason) < 120


@pytest.mark.parametrize('change, item', [
    ({'scene': {'objects': {1: 'no_such_body'}}}, None),
    ({'scene': {'objects': {'one': 'pickup_object'}}}, 'one'),
    ({'scene': {'reach': -1}}, 'scene.reach'),
    ({'scene': {'where': 1}}, 'where'),
    ({'scenario': {'operator_answers': {'object_template': 5}}}, 'object_template'),
    ({'scenario': {'operator_answers': {'look_down': 5}}}, 'look_down'),
])
def test_bad_scene_and_answers_name_the_item(document, change, item):
    with pytest.raises((SimulationConfigError, KeyError)) as raised:
        simulator(document, **change)
    if item is not None:
        assert raised.value.item == item
    else:
        assert 'no_such_body' in str(raised.value)


def test_only_operator_inputs_provide_data(document):
    document = copy.deepcopy(document)
    document['simulation']['actions']['look_down']['provides'] = 'template_id'
    with pytest.raises(SimulationConfigError) as raised:
        AtlasSimulator(SystemConfig.from_dict(document))
    assert raised.value.item == 'look_down'


def test_answers_are_pickled_as_flexbe_input_does_and_read_back_as_input_state_does():
    import ast
    import pickle

    from atlas_sim.simulator.operator_data import flexbe_input_data

    for value in (1, [0.6, 0.0, 0.0]):
        assert pickle.loads(ast.literal_eval(flexbe_input_data(value))) == value


def test_the_configured_operator_answers_by_request_type():
    from respec.robot import robot_system
    from synthesis_manager.nodes.operator_node import configured_answers

    assert configured_answers(robot_system('atlas')) == {0: 1, 3: [0.6, 0.0, 0.0]}
    assert configured_answers(robot_system('mobile_manipulator')) == {}


@pytest.mark.parametrize('entries, item', [
    (['0'], '0'), (['x=1'], 'x'), (['300=1'], '300'), (['0=[1,'], '0=[1,'), ({'zero': 1}, 'zero'),
    (['0=\x07'], '0=\x07')])  # a character YAML refuses to read (its ReaderError has no ``problem``)
def test_bad_answers_name_the_entry(entries, item):
    from atlas_sim.simulator.operator_data import parse_answers

    with pytest.raises(SimulationConfigError) as raised:
        parse_answers(entries, '--answer')
    assert raised.value.item == item


def test_answers_from_text_and_files():
    from atlas_sim.simulator.operator_data import parse_answers

    assert parse_answers(['0=7', '3=[1, 2, 0.5]'], '--answer') == {0: 7, 3: [1, 2, 0.5]}
    assert parse_answers({0: 2}, 'scenario.yaml') == {0: 2}


def test_the_operator_command_refuses_a_bad_answer_before_starting_ros():
    import subprocess
    import sys
    from pathlib import Path

    command = Path(sys.executable).parent / 'atlas-sim-operator'
    done = subprocess.run([str(command), '--answer', 'zero'], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert "--answer: expected TYPE=VALUE, got 'zero'" in done.stderr
    shown = subprocess.run([str(command), '--help'], capture_output=True, text=True, timeout=60)
    assert shown.returncode == 0 and 'flexbe/behavior_input' in shown.stdout and '(default: atlas)' in shown.stdout
