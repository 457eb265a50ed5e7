"""Request bounds (ROS-free): time limits and their cap, string and list lengths, whole-message
size and control characters, refused without echoing."""

import math

import pytest

from synthesis_manager.limits import (MAX_LIST_LENGTH, MAX_MESSAGE_BYTES, MAX_STRING_BYTES, GoalDeadline,
                                      capped_timeout, check_message, check_timeout, oversized_strings)
from synthesis_manager.requests import InvalidRequestError

pytestmark = pytest.mark.ros


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


# Whole-message bounds and control characters (issue 34, items 6 and 11).

def behavior_goal(**request):
    from synthesis_msgs.action import BehaviorSynthesis

    goal = BehaviorSynthesis.Goal()
    goal.request.name = 'ok'
    for field, value in request.items():
        setattr(goal.request, field, value)
    return goal


def refusal(goal) -> InvalidRequestError:
    with pytest.raises(InvalidRequestError) as raised:
        check_message(goal, 'goal')
    assert raised.value.code == 'INVALID_REQUEST'
    assert len(str(raised.value)) < 300
    return raised.value


def flexbe_goal(**request):
    from synthesis_msgs.action import FlexBESynthesis

    goal = FlexBESynthesis.Goal()
    for field, value in request.items():
        setattr(goal.request, field, value)
    return goal


def test_a_long_goal_list_is_refused_naming_the_field():
    error = refusal(flexbe_goal(goals=['stand'] * (MAX_LIST_LENGTH + 1)))
    assert f'goal.request.goals has {MAX_LIST_LENGTH + 1} elements' in str(error)
    assert error.item == 'goal.request.goals'
    check_message(flexbe_goal(goals=['stand'] * MAX_LIST_LENGTH), 'goal')


def test_a_message_over_the_whole_bound_is_refused():
    """Each formula is within the string bound, the list within its length: only the sum is too big."""
    formula = 'x & ' * (MAX_STRING_BYTES // 4 - 1) + 'x'
    count = MAX_MESSAGE_BYTES // len(formula) + 1
    goal = behavior_goal()
    goal.request.ltl_specification.sys_trans = [formula] * count
    error = refusal(goal)
    assert f'over {MAX_MESSAGE_BYTES} bytes in all' in str(error)
    assert f'sys_trans[{count - 1}]' in str(error)


def test_a_nul_in_a_goal_is_refused_not_truncated():
    error = refusal(flexbe_goal(goals=['stand', 'walk\x00_to_the_door']))
    assert 'goal.request.goals[1]' in str(error) and 'U+0000 at character 4' in str(error)
    error = refusal(behavior_goal(goal='stand, walk\x00_to_the_door'))
    assert 'goal.request.goal ' in str(error) and 'U+0000 at character 11' in str(error)


@pytest.mark.parametrize('field, value', [('name', 'my\nbehavior'), ('system', 'atlas\t'), ('name', 'a\x85b'),
                                          ('sm_outcomes', ['finished', 'fail\x1bed'])])
def test_control_characters_in_names_are_refused(field, value):
    error = refusal(behavior_goal(**{field: value}))
    assert f'goal.request.{field}' in str(error)


def test_formulas_keep_their_tabs_and_line_breaks_but_no_other_control():
    goal = behavior_goal()
    goal.request.ltl_specification.sys_trans = ['x\n  & y\t| z\r\n']
    check_message(goal, 'goal')
    goal.request.ltl_specification.sys_trans = ['x \x07 y']
    assert 'sys_trans[0]' in str(refusal(goal))


# The server's cap on a goal's time limit (issue 34, item 5).

@pytest.mark.parametrize('requested, cap, limit', [(1e9, 600, 600), (5, 600, 5), (0, 600, 0), (1e9, 0, 1e9)])
def test_a_goal_time_limit_is_capped(requested, cap, limit):
    assert capped_timeout(requested, cap) == limit


def test_a_capped_deadline_names_the_cap_and_the_request():
    deadline = GoalDeadline(capped_timeout(1e9, 0.01), requested=1e9)
    assert 'asked for 1e+09 s' in deadline.capped() and 'max_goal_timeout caps it at 0.01 s' in deadline.capped()
    assert 'max_goal_timeout' in str(deadline.timed_out('LTL synthesis'))
    assert GoalDeadline(5, requested=5).capped() == ''
    assert 'max_goal_timeout' not in str(GoalDeadline(5, requested=5).timed_out('LTL synthesis'))
