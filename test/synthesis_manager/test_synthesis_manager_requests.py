"""Reading requests of both action interfaces into one task (ROS-free parts)."""

from types import SimpleNamespace

import pytest
from hypothesis import given, settings, strategies as st

from synthesis_manager.byproducts import InvalidSpecNameError, checked_spec_name
from synthesis_manager.requests import (InvalidRequestError, behavior_name, byproduct_file_stem,
                                        parse_synthesis_options, resolve_system,
                                        task_from_behavior_synthesis, task_from_flexbe_synthesis)

pytestmark = pytest.mark.ros


def test_container_paths_name_the_behavior():
    assert behavior_name('/Container') == 'Container'
    assert behavior_name('/Outer/Inner/Sub') == 'Outer/Inner/Sub'
    assert behavior_name('plain_name') == 'plain_name'
    assert behavior_name('//a//b/') == 'a/b'
    assert behavior_name('') == ''


def test_byproduct_stems_are_readable_for_ordinary_names():
    assert byproduct_file_stem('/Container') == 'Container'
    assert byproduct_file_stem('/Outer/Inner/Sub') == 'Outer.Inner.Sub'
    assert byproduct_file_stem('look_down') == 'look_down'
    assert byproduct_file_stem('a.b') == 'a-2eb'
    assert byproduct_file_stem('a.c') == 'a-2ec'
    assert byproduct_file_stem('../../etc/passwd') == 'x--2e-2e.-2e-2e.etc.passwd'
    assert byproduct_file_stem('_hidden') == 'x-_hidden'


def test_different_names_never_share_a_stem():
    names = ['a.b', 'a.c', 'a_b', 'a/b', 'a-b', 'a b', '_a', 'x-_a', 'x--2ea', '.a', 'x-2ea',
             'Ä', 'A', '/A', 'A/', 'x-', '-', '0-2e', '0.', '0/.', 'x' * 150, 'x' * 151]
    stems = {name: byproduct_file_stem(name) for name in names}
    by_behavior = {}
    for name, stem in stems.items():
        by_behavior.setdefault(stem, set()).add(behavior_name(name))
    assert all(len(behaviors) == 1 for behaviors in by_behavior.values()), by_behavior


@settings(deadline=None)
@given(st.text(min_size=1, max_size=160).filter(lambda name: behavior_name(name)))
def test_every_stem_is_a_valid_spec_name_inside_the_directory(name):
    stem = byproduct_file_stem(name)
    assert checked_spec_name(stem) == stem


@settings(deadline=None)
@given(st.text(max_size=30), st.text(max_size=30))
def test_stems_of_different_behaviors_differ(first, second):
    if behavior_name(first) and behavior_name(second) and behavior_name(first) != behavior_name(second):
        assert byproduct_file_stem(first) != byproduct_file_stem(second)


def test_system_wide_and_empty_mean_the_default_system():
    assert resolve_system('system_wide', 'atlas') == 'atlas'
    assert resolve_system('', 'atlas') == 'atlas'
    assert resolve_system(' ', 'youbot') == 'youbot'
    assert resolve_system('baxter', 'atlas') == 'baxter'


@pytest.mark.parametrize('text, expected', [
    ('', {'option': None, 'timeout': 0.0, 'unordered_goals': False}),
    ('  \n', {'option': None, 'timeout': 0.0, 'unordered_goals': False}),
    ('ltl_compilation_only', {'option': 'ltl_compilation_only', 'timeout': 0.0, 'unordered_goals': False}),
    ('{ltl_steps_only: true, timeout: 30}', {'option': 'ltl_steps_only', 'timeout': 30.0,
                                            'unordered_goals': False}),
    ('unordered_goals: true\nltl_compilation_only: false',
     {'option': None, 'timeout': 0.0, 'unordered_goals': True}),
])
def test_synthesis_options_yaml(text, expected):
    assert parse_synthesis_options(text) == expected


@pytest.mark.parametrize('text, named', [
    ('{ltl_steps_only: [', 'not valid YAML'),
    ('[1, 2]', 'must be a YAML mapping'),
    ('stop_early: true', "'stop_early'"),
    ('timeout: soon', 'timeout'),
    ('timeout: -1', 'timeout'),
    ('ltl_steps_only: maybe', 'ltl_steps_only'),
    ('{ltl_steps_only: true, ltl_compilation_only: true}', 'mutually exclusive'),
    ('timeout: ' + '9' * 60_000, 'an integer has more than 4300 digits'),  # Python's int-string limit
])
def test_bad_synthesis_options_are_invalid_requests(text, named):
    with pytest.raises(InvalidRequestError, match=named):
        parse_synthesis_options(text)


def test_the_synthesizer_still_refuses_names_that_leave_its_directory():
    for name in ('../escape', 'a/b', '.hidden', 'a..b'):
        with pytest.raises(InvalidSpecNameError, match='invalid spec_name'):
            checked_spec_name(name)


def flexbe_goal(**request_fields):
    request = dict(initial_conditions=['stand_prep'], goals=['look_down, pickup_object'], sm_outcomes=[],
                   system_name='system_wide', spec_name='/Container', specification_file_name='',
                   synthesis_timeout_s=0.0)
    request.update(request_fields)
    return SimpleNamespace(request=SimpleNamespace(**request), synthesis_options='')


def test_both_interfaces_read_into_the_same_task():
    legacy = SimpleNamespace(
        request=SimpleNamespace(system='system_wide', initial_condition='stand_prep',
                                goal='look_down pickup_object', sm_outcomes=[], name='/Container',
                                timeout=0.0, unordered_goals=False, ltl_specification=None),
        synthesis_options=SimpleNamespace(ltl_compilation_only=False, ltl_synthesis_only=False,
                                          ltl_steps_only=False))
    assert task_from_behavior_synthesis(legacy, 'atlas') == task_from_flexbe_synthesis(flexbe_goal(), 'atlas')
    task = task_from_flexbe_synthesis(flexbe_goal(), 'atlas')
    assert (task.system, task.goals, task.sm_outcomes, task.byproduct_stem) == (
        'atlas', ['look_down', 'pickup_object'], ['finished', 'failed'], 'Container')


def test_flexbe_timeout_field_wins_over_the_options_timeout():
    goal = flexbe_goal(synthesis_timeout_s=12.5)
    goal.synthesis_options = 'timeout: 30'
    assert task_from_flexbe_synthesis(goal, 'atlas').timeout == 12.5
    goal.request.synthesis_timeout_s = 0.0
    assert task_from_flexbe_synthesis(goal, 'atlas').timeout == 30.0


@pytest.mark.parametrize('fields, options, named', [
    ({'specification_file_name': 'mine.yaml'}, '', 'mine.yaml'),
    ({}, 'ltl_synthesis_only', 'ltl_synthesis_only'),
])
def test_flexbe_requests_this_server_cannot_serve_are_invalid(fields, options, named):
    goal = flexbe_goal(**fields)
    goal.synthesis_options = options
    with pytest.raises(InvalidRequestError, match=named):
        task_from_flexbe_synthesis(goal, 'atlas')
