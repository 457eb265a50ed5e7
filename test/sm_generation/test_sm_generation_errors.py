"""Every SMGenerationError code, each naming the offending item."""

from pathlib import Path

import pytest
import yaml

from sm_generation import SMGenerationError, generate_state_machine, load_automaton
from sm_generation import errors
from respec.robot import robot_system
from sm_generation.config import generation_system_errors

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'
ATLAS = Path(__file__).resolve().parents[2] / 'config' / 'atlas.yaml'


def fails(automaton_file, code, item, system='atlas', config_dir=None, **kwargs):
    """The error generating gives, its system read by name as the edges read it."""
    with pytest.raises(SMGenerationError) as caught:
        with generation_system_errors():
            robot = robot_system(system, config_dir)
        generate_state_machine(load_automaton(AUTOMATA / automaton_file), robot, **kwargs).to_instantiations()
    assert caught.value.code == code, str(caught.value)
    assert caught.value.item == item
    return caught.value


@pytest.mark.parametrize('name, code, item', [
    ('bad_next_state', 'AUTOMATON_NEXT_STATE_INVALID', '7'),
    ('bad_input_valuation', 'AUTOMATON_INPUT_VALUATION_INVALID', '1'),
    ('two_outcomes_at_once', 'AUTOMATON_INPUT_VALUATION_INVALID', '2'),
    ('bad_output_valuation', 'AUTOMATON_OUTPUT_VALUATION_INVALID', '1'),
    ('duplicate_names', 'AUTOMATON_INVALID', '1'),
    ('empty', 'AUTOMATON_INVALID', 'states'),
    ('two_sm_outcomes', 'AUTOMATON_INVALID', '2'),
    ('dead_end', 'AUTOMATON_INVALID', '2'),
    ('bad_initial_state', 'AUTOMATON_INVALID', '9'),
    ('no_initial_state', 'AUTOMATON_NO_INITIAL_STATE', ''),
    ('unconfigured_activation', 'CONFIG_VARIABLE_CONFIG_INVALID', 'dance_a'),
    ('unobserved_input', 'CONFIG_VARIABLE_CONFIG_INVALID', 'door_open'),
])
def test_invalid_automata(name, code, item):
    error = fails(f'invalid/{name}.yaml', code, item)
    assert item in str(error)  # the message names the item too


def test_unreadable_automaton_files(tmp_path):
    with pytest.raises(SMGenerationError) as caught:
        load_automaton(AUTOMATA / 'invalid' / 'not_a_mapping.yaml')
    assert caught.value.code == 'AUTOMATON_INVALID'
    with pytest.raises(SMGenerationError) as caught:
        load_automaton(tmp_path / 'missing.yaml')
    assert caught.value.code == 'AUTOMATON_INVALID' and caught.value.item.endswith('missing.yaml')
    (tmp_path / 'broken.yaml').write_text('automaton: [unclosed')
    with pytest.raises(SMGenerationError) as caught:
        load_automaton(tmp_path / 'broken.yaml')
    assert caught.value.code == 'AUTOMATON_INVALID'


def test_slugs_strategy_needs_its_specification(tmp_path):
    (tmp_path / 'strategy.json').write_text('{"version": 0, "variables": [], "nodes": {}}')
    with pytest.raises(SMGenerationError, match='structuredslugs') as caught:
        load_automaton(tmp_path / 'strategy.json')
    assert caught.value.code == 'AUTOMATON_INVALID'


def test_initial_conditions_that_match_no_state():
    # unknown to the system
    error = fails('no_initial_states.yaml', 'INVALID_INITIAL_CONDITIONS', 'fly', initial_conditions=['fly'])
    assert "'fly'" in str(error)
    # a known proposition that no start state has
    fails('no_initial_states.yaml', 'AUTOMATON_NO_INITIAL_STATE', 'look_down',
          initial_conditions=['look_down'])


def test_unknown_system():
    fails('look_down.yaml', 'NO_SYSTEM_CONFIG', 'marsrover', system='marsrover')


def test_missing_config_directory(tmp_path):
    fails('look_down.yaml', 'SYSTEM_CONFIG_NOT_FOUND', str(tmp_path / 'nowhere'), config_dir=tmp_path / 'nowhere')


def _config(tmp_path, edit):
    document = yaml.safe_load(ATLAS.read_text())
    edit(document)
    (tmp_path / 'atlas.yaml').write_text(yaml.safe_dump(document))
    return tmp_path


def test_invalid_yaml_and_missing_section(tmp_path):
    (tmp_path / 'atlas.yaml').write_text('flexbe: [unclosed')
    fails('look_down.yaml', 'CONFIG_FILE_INVALID', str(tmp_path / 'atlas.yaml'), config_dir=tmp_path)
    _config(tmp_path, lambda d: d.pop('flexbe'))
    fails('look_down.yaml', 'CONFIG_FILE_INVALID', 'flexbe', config_dir=tmp_path)
    _config(tmp_path, lambda d: d['flexbe'].pop('sm_outcomes'))
    fails('look_down.yaml', 'CONFIG_FILE_INVALID', 'flexbe.sm_outcomes', config_dir=tmp_path)
    _config(tmp_path, lambda d: d['flexbe'].pop('states'))
    fails('look_down.yaml', 'CONFIG_FILE_INVALID', 'flexbe.states', config_dir=tmp_path)


def _set(path, value):
    def edit(document):
        node = document['flexbe']['states']
        for key in path[:-1]:
            node = node[key]
        if value is KeyError:
            del node[path[-1]]
        else:
            node[path[-1]] = value
    return edit


@pytest.mark.parametrize('path, value, code, item', [
    (('stand_a', 'autonomy'), 7, 'CONFIG_AUTONOMY_INVALID', 'flexbe.states.stand_a.autonomy'),
    (('stand_a', 'autonomy'), [0, 1, 2], 'CONFIG_AUTONOMY_INVALID', 'flexbe.states.stand_a.autonomy'),
    (('stand_a', 'autonomy'), 'high', 'CONFIG_AUTONOMY_INVALID', 'flexbe.states.stand_a.autonomy'),
    (('stand_a', 'userdata_keys'), ['a', 'b'], 'CONFIG_USERDATA_INVALID', 'flexbe.states.stand_a.userdata_remapping'),
    (('stand_a', 'userdata_keys'), 'a', 'CONFIG_USERDATA_INVALID', 'flexbe.states.stand_a.userdata_keys'),
    (('stand_a', 'class_decl', 'param_values'), [], 'CONFIG_VARIABLE_CONFIG_INVALID',
     'flexbe.states.stand_a.class_decl.param_values'),
    (('stand_a', 'class_decl'), KeyError, 'CONFIG_VARIABLE_CONFIG_INVALID', 'flexbe.states.stand_a.class_decl'),
    (('stand_a', 'output_mapping'), KeyError, 'CONFIG_VARIABLE_CONFIG_INVALID',
     'flexbe.states.stand_a.output_mapping'),
    (('stand_a', 'output_mapping', 'stand_f'), [], 'CONFIG_VARIABLE_CONFIG_INVALID',
     'flexbe.states.stand_a.output_mapping.stand_f'),
    (('stand_a', 'output_mapping', 'stand_f'), ['changed'], 'CONFIG_VARIABLE_CONFIG_INVALID',
     'flexbe.states.stand_a.output_mapping.stand_f'),
    (('look_down_a', 'output_mapping', 'stand_c'), ['done'], 'CONFIG_VARIABLE_CONFIG_INVALID',
     'flexbe.states.look_down_a.output_mapping.stand_c'),
    (('pickup_object_a', 'class_decl', 'behavior_class'), KeyError, 'CONFIG_VARIABLE_CONFIG_INVALID',
     'flexbe.states.pickup_object_a.class_decl.behavior_class'),
])
def test_invalid_state_entries(tmp_path, path, value, code, item):
    fails('look_down.yaml', code, item, config_dir=_config(tmp_path, _set(path, value)))


def test_state_entry_that_is_no_mapping(tmp_path):
    fails('look_down.yaml', 'CONFIG_VARIABLE_CONFIG_INVALID', 'flexbe.states.stand_a',
          config_dir=_config(tmp_path, _set(('stand_a',), 'ChangeControlModeActionState')))


def test_error_code_names_are_synthesis_error_codes():
    text = (Path(__file__).resolve().parents[2] / 'synthesis_msgs' / 'msg' / 'SynthesisErrorCodes.msg').read_text()
    classes = [c for c in vars(errors).values() if isinstance(c, type) and issubclass(c, SMGenerationError)]
    assert len({c.code for c in classes}) == len(classes) == 13  # one class per code
    for error in classes:
        assert f'int32 {error.code} =' in text, error.__name__


def test_constant_unobserved_input_is_harmless():
    data = yaml.safe_load((AUTOMATA / 'invalid' / 'unobserved_input.yaml').read_text())
    data['automaton'][2]['input_valuation'][3] = 0  # door_open never changes now
    from sm_generation.automaton_io import automaton_from_dict
    states = generate_state_machine(automaton_from_dict(data), robot_system('atlas')).to_instantiations()
    assert [s.name for s in states if s.parent_path == '/'] == ['stand', 'finished', 'failed']
