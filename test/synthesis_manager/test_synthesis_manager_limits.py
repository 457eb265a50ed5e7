"""Request bounds (ROS-free): time limits and string lengths, refused without echoing."""

import math

import pytest

from synthesis_manager.limits import MAX_STRING_BYTES, check_message, check_timeout, oversized_strings
from synthesis_manager.requests import InvalidRequestError


@pytest.mark.parametrize('value', [-1, -0.001, math.nan, math.inf, -math.inf, 'soon'])
def test_bad_time_limits_are_invalid_requests(value):
    with pytest.raises(InvalidRequestError, match='timeout') as raised:
        check_timeout(value)
    assert raised.value.code == 'INVALID_REQUEST'


@pytest.mark.parametrize('value', [0, 0.5, 120])
def test_good_time_limits_pass(value):
    assert check_timeout(value) == float(value)


def test_an_oversized_nested_string_is_named_and_not_echoed():
    from synthesis_msgs.action import BehaviorSynthesis

    goal = BehaviorSynthesis.Goal()
    goal.request.name = 'ok'
    goal.request.ltl_specification.sys_trans = ['x', 'y' * (MAX_STRING_BYTES + 1)]
    with pytest.raises(InvalidRequestError) as raised:
        check_message(goal, 'goal')
    message = str(raised.value)
    assert 'goal.request.ltl_specification.sys_trans[1]' in message
    assert str(MAX_STRING_BYTES + 1) in message
    assert len(message) < 300


def test_multibyte_text_counts_in_bytes():
    text = '\u00e9' * (MAX_STRING_BYTES // 2 + 1)  # fewer characters than the limit, more bytes
    assert [path for path, _ in oversized_strings(text, 'name')] == ['name']
    assert not list(oversized_strings('\u00e9' * (MAX_STRING_BYTES // 2), 'name'))


def test_json_bodies_are_searched_keys_included():
    big = 'k' * (MAX_STRING_BYTES + 1)
    found = list(oversized_strings({'goals': ['a', big], big: 1}, 'body'))
    assert [path for path, _ in found] == ['body.goals[1]', 'body (a key)']
