"""generate_state_machine on hand-written automata (test/automata/): every branch."""

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from sm_generation import (Automaton, AutomatonState, StateInstantiation, StateMachine, generate_state_machine,
                           load_automaton, validate_state_machine)
from sm_generation.automaton_io import automaton_from_dict, automaton_to_dict, dump_automaton
from sm_generation.export import to_yaml
from respec.robot import robot_system

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'
VALID = sorted(AUTOMATA.glob('*.yaml'))
REPO_CONFIG = Path(__file__).resolve().parents[2] / 'config'


def generate(name, system='atlas', **kwargs):
    machine = generate_state_machine(load_automaton(AUTOMATA / name), robot_system(system), **kwargs)
    assert validate_state_machine(machine.to_instantiations()) == []
    return machine


def by_path(machine):
    return {s.state_path: s for s in machine.walk()}


def edges(state):
    return dict(zip(state.outcomes, state.transitions))


@pytest.mark.parametrize('path', VALID, ids=lambda p: p.stem)
@pytest.mark.parametrize('reduce', [False, True])
def test_every_fixture_gives_a_consistent_machine(path, reduce):
    states = generate_state_machine(load_automaton(path), robot_system('atlas'), reduce=reduce).to_instantiations()
    assert validate_state_machine(states) == []
    root = states[0]
    assert root.state_path == '/' and root.state_class == ':STATEMACHINE'
    assert root.outcomes == ['finished', 'failed'] and root.transitions == root.outcomes
    top = [s for s in states if s.parent_path == '/' and s.state_class != ':OUTCOME']
    assert root.initial_state_name in {s.name for s in top}
    for state in states:
        assert len(state.to_dict()) == 16
        assert len(state.position) == 2
        assert len(state.outcomes) == len(state.transitions) == len(state.autonomy)
    # machine outcomes are placed in the drawing by :OUTCOME entries
    assert [s.state_path for s in states if s.state_class == ':OUTCOME'] == ['/finished', '/failed']


@pytest.mark.parametrize('path', VALID, ids=lambda p: p.stem)
def test_same_automaton_same_bytes(path):
    first = to_yaml(generate_state_machine(load_automaton(path), robot_system('atlas')))
    second = to_yaml(generate_state_machine(load_automaton(path), robot_system('atlas')))
    assert first == second


@pytest.mark.parametrize('name', ['concurrent.yaml', 'sensors.yaml', 'initial_decision.yaml'])
def test_order_of_states_in_the_file_does_not_matter(name):
    data = yaml.safe_load((AUTOMATA / name).read_text())
    expected = to_yaml(generate_state_machine(automaton_from_dict(data), robot_system('atlas')))
    shuffler = random.Random(7)
    for _ in range(5):
        shuffled = dict(data, automaton=shuffler.sample(data['automaton'], len(data['automaton'])))
        assert to_yaml(generate_state_machine(automaton_from_dict(shuffled), robot_system('atlas'))) == expected


def test_sequence_of_single_states():
    states = by_path(generate('look_down.yaml'))
    assert states['/'].initial_state_name == 'stand'  # the start state activates nothing: passed through
    stand, look = states['/stand'], states['/look_down']
    assert stand.state_class == 'ChangeControlModeActionState'
    assert stand.parameter_names == ['target_mode']
    assert stand.parameter_values == ['"stand"']  # ChangeControlModeActionState.STAND's value
    assert edges(stand) == {'changed': 'look_down', 'failed': 'failed'}
    assert look.state_class == 'TiltHeadState'
    assert edges(look) == {'done': 'finished', 'failed': 'failed'}  # SM-outcome states become outcomes
    assert set(states) == {'/', '/stand', '/look_down', '/finished', '/failed'}


def test_concurrency_container_conditions():
    states = by_path(generate('concurrent.yaml'))
    container = states['/object_template_and_stand']
    assert states['/'].initial_state_name == 'object_template_and_stand'
    assert container.state_class == ':CONCURRENCY'
    assert edges(container) == {
        'object_template_c__stand_c': 'pregrasp_pose',
        'object_template_f__stand_c': 'failed',
        'object_template_f': 'failed',
        'stand_c': 'object_template',   # the template request goes on in its own state
        'stand_f': 'failed',
    }
    conditions = [(o, list(zip(c.state_name, c.state_outcome)))
                  for o, c in zip(container.cond_outcome, container.cond_transition)]
    # both parts reporting come first (FlexBE returns the first condition that holds)
    assert conditions[0] == ('object_template_c__stand_c', [('object_template', 'received'), ('stand', 'changed')])
    # object_template_f means three InputState outcomes: one condition each
    failing = [c for o, c in conditions if o == 'object_template_f']
    assert failing == [[('object_template', 'aborted')], [('object_template', 'no_connection')],
                       [('object_template', 'data_error')]]
    assert ('stand_c', [('stand', 'changed')]) in conditions
    inner = states['/object_template_and_stand/object_template']
    assert inner.state_class == 'InputState'
    assert inner.userdata_keys == ['data'] and inner.userdata_remapping == ['template_id']
    assert container.input_keys == ['template_id'] and container.output_keys == ['template_id']
    assert edges(states['/object_template_and_stand/stand']) == {
        'changed': 'object_template_c__stand_c', 'failed': 'stand_f'}
    # an outcome proposition with several state outcomes in a plain state
    assert edges(states['/pregrasp_pose']) == {'done': 'finished', 'failed': 'failed', 'not_available': 'failed'}


def test_sensor_states_and_sensor_wait_state():
    states = by_path(generate('sensors.yaml'))
    assert states['/'].initial_state_name == 'stand'  # does not wait for the sensor at the start
    container = states['/look_down_and_obj_detected']
    assert container.state_class == ':CONCURRENCY'
    assert states['/look_down_and_obj_detected/obj_detected'].state_class == 'SensorReading'
    assert edges(container) == {'look_down_c': 'obj_detected', 'look_down_f': 'failed',
                                'obj_detected_true': 'object_template_1'}
    # look_down done, no object yet: a state that activates nothing waits for the sensor
    waiting = states['/obj_detected']
    assert waiting.state_class == 'SensorReading'
    assert edges(waiting) == {'found': 'object_template_2'}
    assert edges(states['/object_template_1']) == edges(states['/object_template_2'])


def test_two_behaviors_in_one_task():
    states = by_path(generate('two_behaviors.yaml'))
    pickup, grasp = states['/pickup_object'], states['/grasp_object']
    assert (pickup.state_class, pickup.behavior_class) == (':BEHAVIOR', 'Pickup Object')
    assert (grasp.state_class, grasp.behavior_class) == (':BEHAVIOR', 'Grasp Object')
    assert edges(pickup) == {'finished': 'grasp_object', 'failed': 'failed'}
    assert edges(grasp) == {'finished': 'finished', 'failed': 'failed'}


def test_several_initial_states_with_the_same_behaviour_pick_the_first():
    machine = generate('initial_same_behaviour.yaml')
    assert machine.initial_state_name == 'stand'
    assert [s.name for s in machine.walk() if s.state_class == 'ChangeControlModeActionState'] == ['stand']


def test_several_initial_states_with_different_behaviours_ask_the_operator():
    states = by_path(generate('initial_decision.yaml'))
    decision = states['/choose_initial_state']
    assert states['/'].initial_state_name == 'choose_initial_state'
    assert decision.state_class == 'OperatorDecisionState'
    assert edges(decision) == {'stand': 'stand', 'look_down': 'look_down'}
    parameters = dict(zip(decision.parameter_names, decision.parameter_values))
    assert parameters['outcomes'] == "['stand', 'look_down']"
    assert parameters['suggestion'] == "'stand'"  # FlexBE takes it in full autonomy, like our executive


def test_initial_state_that_already_exits():
    states = by_path(generate('nothing_to_do.yaml'))
    assert states['/'].initial_state_name == 'nothing_to_do'
    assert states['/nothing_to_do'].state_class == 'LogState'
    assert edges(states['/nothing_to_do']) == {'done': 'finished'}


def test_initial_state_deduced_from_initial_conditions():
    automaton = load_automaton(AUTOMATA / 'no_initial_states.yaml')
    assert automaton.initial_states == []
    # no hint: the state that activates nothing and that nothing enters
    assert generate_state_machine(automaton, robot_system('atlas')).initial_state_name == 'stand'
    assert generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand_prep']).initial_state_name == 'stand'
    # starting from stand: state '6' (stand_c true) is passed through to look_down
    from_stand = generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand'])
    assert from_stand.initial_state_name == 'look_down'
    assert [s.name for s in from_stand.walk() if s.parent_path == '/'] == ['look_down', 'finished', 'failed']
    # manipulate is configured but not in this automaton (irrelevant to the task): no constraint
    assert generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand_prep', 'manipulate']) \
        .initial_state_name == 'stand'
    # a proposition name works as well
    assert generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand_c']).initial_state_name == 'look_down'


def test_pass_through_state_in_the_middle():
    states = by_path(generate('no_initial_states.yaml', initial_conditions=['stand_prep']))
    assert edges(states['/stand'])['changed'] == 'look_down'


def test_reduce_merges_bisimilar_states():
    plain = by_path(generate('sensors.yaml'))
    reduced = by_path(generate('sensors.yaml', reduce=True))
    assert '/object_template_1' in plain and '/object_template_2' in plain
    assert '/object_template' in reduced and '/object_template_1' not in reduced
    assert edges(reduced['/obj_detected']) == {'found': 'object_template'}
    assert edges(reduced['/look_down_and_obj_detected'])['obj_detected_true'] == 'object_template'


def test_names_clash_get_numbered_in_breadth_first_order():
    states = [s.name for s in generate('sensors.yaml').walk() if s.parent_path == '/']
    assert states.index('object_template_1') < states.index('object_template_2')


def test_positions_are_layered_from_the_initial_state():
    states = by_path(generate('look_down.yaml'))
    stand, look = states['/stand'].position, states['/look_down'].position
    finished, failed = states['/finished'].position, states['/failed'].position
    assert stand[1] < look[1] < finished[1] == failed[1]
    assert finished[0] != failed[0]
    inner = by_path(generate('concurrent.yaml'))
    a = inner['/object_template_and_stand/object_template'].position
    b = inner['/object_template_and_stand/stand'].position
    assert a != b and a[1] == b[1]
    top = [s.position for s in generate('sensors.yaml').walk() if s.parent_path == '/']
    assert len({tuple(p) for p in top}) == len(top)  # no two states on top of each other


def test_layers_are_distances_from_the_initial_state_with_unreachable_states_last():
    from sm_generation.layout import COLUMN_SPACING, LAYER_SPACING, layered_positions
    edges = {'a': ['c', 'b', 'a', 'done'], 'b': ['d'], 'c': ['d', 'b'], 'd': ['a'], 'lost': ['a']}
    positions = layered_positions(edges, 'a', ['done'])
    row = {node: round((y - positions['a'][1]) / LAYER_SPACING) for node, (_, y) in positions.items()}
    assert row == {'a': 0, 'b': 1, 'c': 1, 'd': 2, 'lost': 3, 'done': 4}
    assert positions['c'][0] - positions['b'][0] == COLUMN_SPACING  # a layer keeps the order of ``edges``


def test_generation_loads_neither_networkx_nor_logging():
    # networkx's import was most of a small machine's generation (0.1 s); the layout needs a search
    # only. logging (with traceback, 2-3 ms of a fresh process) only when a step is dropped.
    code = ('import sys; from sm_generation import generate_state_machine, load_automaton; '
            'from respec.robot import robot_system; '
            f'generate_state_machine(load_automaton({str(AUTOMATA / "sensors.yaml")!r}), robot_system("atlas")); '
            'print("networkx" in sys.modules, "logging" in sys.modules)')
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[2], timeout=60)
    assert done.stdout.strip() == 'False False', done.stderr


def test_autonomy_levels_come_from_the_configuration(tmp_path):
    config = yaml.safe_load((REPO_CONFIG / 'atlas.yaml').read_text())
    config['flexbe']['states']['stand_a']['autonomy'] = [2, 1]
    config['flexbe']['states']['object_template_a']['autonomy'] = 3
    (tmp_path / 'atlas.yaml').write_text(yaml.safe_dump(config))
    states = by_path(generate_state_machine(load_automaton(AUTOMATA / 'concurrent.yaml'),
                                            robot_system('atlas', tmp_path)))
    assert states['/object_template_and_stand/stand'].autonomy == [2, 1]
    container = states['/object_template_and_stand']
    autonomy = dict(zip(container.outcomes, container.autonomy))
    assert autonomy == {'object_template_c__stand_c': 3, 'object_template_f__stand_c': 3,
                        'object_template_f': 3, 'stand_c': 2, 'stand_f': 1}


def test_another_system_with_other_names(tmp_path):
    """Nothing is ATLAS-specific: other outcome names, SM outcomes and classes."""
    (tmp_path / 'rover.yaml').write_text(yaml.safe_dump({'flexbe': {
        'sm_outcomes': {'done_ok': 'success', 'done_bad': 'failure'},
        'states': {
            'drive_a': {'class_decl': {'name': 'DriveState', 'param_names': ['speed'], 'param_values': [0.5]},
                        'output_mapping': {'drive_s': ['arrived'], 'drive_x': ['stuck']}, 'autonomy': [1, 2]},
            'bump': {'class_decl': {'name': 'BumperState'}, 'output_mapping': {'bump': ['pressed']}},
        }}}))
    automaton = Automaton(
        output_variables=['drive_a', 'done_ok', 'done_bad'], input_variables=['drive_s', 'drive_x', 'bump'],
        states=[AutomatonState('s', [0, 0, 0], [0, 0, 0], ['d'], 0),
                AutomatonState('d', [1, 0, 0], [0, 0, 0], ['d', 'ok', 'bad', 'bumped'], 0),
                AutomatonState('ok', [0, 1, 0], [1, 0, 0], ['ok'], 0),
                AutomatonState('bad', [0, 0, 1], [0, 1, 0], ['bad'], 0),
                AutomatonState('bumped', [0, 0, 1], [0, 0, 1], ['bumped'], 0)],
        initial_states=['s'])
    states = by_path(generate_state_machine(automaton, robot_system('rover', tmp_path)))
    assert validate_state_machine(list(states.values())) == []
    assert states['/'].outcomes == ['success', 'failure']
    assert states['/'].initial_state_name == 'drive_and_bump'
    container = states['/drive_and_bump']
    assert edges(container) == {'drive_s': 'success', 'drive_x': 'failure', 'bump_true': 'failure'}
    assert states['/drive_and_bump/drive'].parameter_values == ['0.5']
    assert states['/drive_and_bump/drive'].autonomy == [1, 2]


def test_mobile_manipulator_configuration_is_usable():
    if not (REPO_CONFIG / 'mobile_manipulator.yaml').exists():
        pytest.fail('config/mobile_manipulator.yaml is expected in the repository')
    automaton = Automaton(
        output_variables=['localize_a', 'navigate_a', 'finished', 'failed'],
        input_variables=['parked_c', 'localize_c', 'localize_f', 'navigate_c', 'navigate_f'],
        states=[AutomatonState('0', [0, 0, 0, 0], [1, 0, 0, 0, 0], ['1'], 0),
                AutomatonState('1', [1, 0, 0, 0], [1, 0, 0, 0, 0], ['1', '2', '4'], 0),
                AutomatonState('2', [0, 1, 0, 0], [1, 1, 0, 0, 0], ['2', '3', '5'], 0),
                AutomatonState('3', [0, 0, 1, 0], [1, 1, 0, 1, 0], ['3'], 0),
                AutomatonState('4', [0, 0, 0, 1], [1, 0, 1, 0, 0], ['4'], 0),
                AutomatonState('5', [0, 0, 0, 1], [1, 1, 0, 0, 1], ['5'], 0)],
        initial_states=['0'])
    states = by_path(generate_state_machine(automaton, robot_system('mobile_manipulator')))
    assert validate_state_machine(list(states.values())) == []
    assert edges(states['/navigate']) == {'arrived': 'finished', 'failed': 'failed', 'blocked': 'failed'}
    assert states['/localize'].userdata_remapping == ['robot_pose']


def test_dataclass_automaton_with_int_names_and_bool_valuations():
    automaton = automaton_from_dict(yaml.safe_load((AUTOMATA / 'look_down.yaml').read_text()))
    for state in automaton.states:
        state.output_valuation = [bool(v) for v in state.output_valuation]
    assert to_yaml(generate_state_machine(automaton, robot_system('atlas'))) == to_yaml(generate('look_down.yaml'))


def test_automaton_file_round_trip(tmp_path):
    automaton = load_automaton(AUTOMATA / 'concurrent.yaml')
    (tmp_path / 'a.yaml').write_text(dump_automaton(automaton))
    assert automaton_to_dict(load_automaton(tmp_path / 'a.yaml')) == automaton_to_dict(automaton)
    (tmp_path / 'a.json').write_text(json.dumps(automaton_to_dict(automaton)))
    assert automaton_to_dict(load_automaton(tmp_path / 'a.json')) == automaton_to_dict(automaton)


def test_returns_the_tree_whose_list_is_plain_state_instantiations():
    machine = generate('two_behaviors.yaml')
    assert isinstance(machine, StateMachine) and machine.state_path == '/'
    assert all(type(s) is StateInstantiation for s in machine.to_instantiations())


def test_silent_change_of_activations_is_left_out_and_reported(caplog):
    """A step that switches activations without any outcome cannot be taken by FlexBE."""
    data = yaml.safe_load((AUTOMATA / 'look_down.yaml').read_text())
    # '1' (stand running) may silently switch to look_down ('2x', stand_prep_c still true)
    data['automaton'][1]['transitions'] = ['1', '2x', '2', '5']
    data['automaton'].append({'name': '2x', 'output_valuation': [0, 1, 0, 0],
                              'input_valuation': [1, 0, 0, 0, 0, 0], 'transitions': ['2x', '3', '4']})
    with caplog.at_level('WARNING', logger='sm_generation.generator'):
        machine = generate_state_machine(automaton_from_dict(data), robot_system('atlas'))
    assert validate_state_machine(machine.to_instantiations()) == []
    assert to_yaml(machine) == to_yaml(generate('look_down.yaml'))
    assert any('1 -> 2x' in record.getMessage() for record in caplog.records)


def test_stay_in_an_equal_state_keeps_running():
    """A silent step to another state with the same activations is a "stay": its outcomes count."""
    data = yaml.safe_load((AUTOMATA / 'look_down.yaml').read_text())
    # stand running moves silently to '1y' (same activation), which alone sees stand fail
    data['automaton'][1]['transitions'] = ['1y', '2']
    data['automaton'].append({'name': '1y', 'output_valuation': [1, 0, 0, 0],
                              'input_valuation': [1, 0, 0, 0, 0, 0], 'transitions': ['1y', '2', '5']})
    states = by_path(generate_state_machine(automaton_from_dict(data), robot_system('atlas')))
    assert edges(states['/stand']) == {'changed': 'look_down', 'failed': 'failed'}


def test_same_bytes_across_processes_with_different_hash_seeds():
    outputs = set()
    for seed in ('1', '2', '3'):
        result = subprocess.run(
            [sys.executable, '-m', 'sm_generation', '--automaton', str(AUTOMATA / 'sensors.yaml'), '--reduce'],
            capture_output=True, check=True, cwd=Path(__file__).resolve().parents[2],
            env=dict(os.environ, PYTHONHASHSEED=seed))
        outputs.add(result.stdout)
    assert len(outputs) == 1
    assert outputs.pop() == to_yaml(generate('sensors.yaml', reduce=True)).encode()


def test_decision_offers_one_choice_per_behaviour():
    states = by_path(generate('initial_three_starts.yaml'))
    assert edges(states['/choose_initial_state']) == {'stand': 'stand', 'look_down': 'look_down'}
    assert [s.name for s in states.values() if s.state_class == 'ChangeControlModeActionState'] == ['stand']
