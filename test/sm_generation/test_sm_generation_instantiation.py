"""StateInstantiation / OutcomeCondition: exactly the message fields, dict round trips."""

import re
from pathlib import Path

import pytest

from sm_generation import OutcomeCondition, StateInstantiation
from sm_generation.instantiation import FIELD_NAMES

MSG_DIR = Path(__file__).resolve().parents[2] / 'synthesis_msgs' / 'msg'


def _message_fields(name: str) -> list[str]:
    fields = []
    for line in (MSG_DIR / name).read_text().splitlines():
        line = line.split('#', 1)[0].strip()
        if line and '=' not in line:  # constants have '='
            fields.append(line.split()[1])
    return fields


def test_fields_are_those_of_the_message_in_order():
    assert list(FIELD_NAMES) == _message_fields('StateInstantiation.msg')
    assert len(FIELD_NAMES) == 16
    assert list(OutcomeCondition().to_dict()) == _message_fields('OutcomeCondition.msg')


def test_class_constants_match_the_message():
    text = (MSG_DIR / 'StateInstantiation.msg').read_text()
    constants = dict(re.findall(r'string (CLASS_\w+) = (\S+)', text))
    for name, value in constants.items():
        assert getattr(StateInstantiation, name) == value
    assert StateInstantiation.CLASS_OUTCOME == ':OUTCOME'


def test_defaults_are_empty_and_position_has_two_floats():
    state = StateInstantiation()
    assert state.position == [0.0, 0.0]
    assert state.outcomes == [] and state.cond_transition == []
    other = StateInstantiation()
    other.outcomes.append('done')
    assert state.outcomes == []  # no shared mutable defaults


def test_to_dict_from_dict_round_trip():
    state = StateInstantiation(
        state_path='/a_and_b', state_class=':CONCURRENCY', initial_state_name='a',
        input_keys=['k'], output_keys=['k'], cond_outcome=['x'],
        cond_transition=[OutcomeCondition(['a', 'b'], ['done', 'changed'])],
        position=[1, 2], outcomes=['x'], transitions=['next'], autonomy=[2],
        userdata_keys=[], userdata_remapping=[])
    data = state.to_dict()
    assert list(data) == list(FIELD_NAMES)
    assert data['cond_transition'] == [{'state_name': ['a', 'b'], 'state_outcome': ['done', 'changed']}]
    assert data['position'] == [1.0, 2.0]
    assert StateInstantiation.from_dict(data) == state


def test_from_dict_rejects_unknown_fields():
    with pytest.raises(ValueError, match='statepath'):
        StateInstantiation.from_dict({'statepath': '/x'})


def test_name_and_parent_path():
    assert StateInstantiation(state_path='/').name == ''
    assert StateInstantiation(state_path='/stand').name == 'stand'
    assert StateInstantiation(state_path='/stand').parent_path == '/'
    assert StateInstantiation(state_path='/c/inner').name == 'inner'
    assert StateInstantiation(state_path='/c/inner').parent_path == '/c'
