"""compile_task: pertinence, formulas, determinism and every kind of bad input."""

import textwrap

import pytest
import yaml
from hypothesis import given, settings, strategies as st

from ltl_specification import (
    InvalidAbstractionError, InvalidFormulaError, InvalidGoalsError, InvalidInitialConditionsError,
    InvalidSmOutcomesError, SpecificationError, UnknownPropositionError, UnknownSystemError, compile_task,
    explain,
)
from ltl_specification.pertinence import infer_pertinence
from respec.robot.abstraction import abstraction_from_dict
from respec.robot import robot_system
from ltl_specification.systems import task_system_errors


def text(spec):
    return spec.to_text_sections()


# --- the paper's demo tasks ---------------------------------------------------------------------

def test_paper_demo_look_down_then_pickup():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'])
    p = spec.provenance.pertinence
    assert p.modes == ('stand_prep', 'stand', 'manipulate')
    assert p.actions == ('look_down', 'pickup_object', 'object_template')
    assert spec.env_props == [
        'stand_prep_c', 'stand_prep_f', 'stand_c', 'stand_f', 'manipulate_c', 'manipulate_f',
        'look_down_c', 'look_down_f', 'pickup_object_c', 'pickup_object_f',
        'object_template_c', 'object_template_f']
    assert spec.sys_props == [
        'stand_prep_a', 'stand_a', 'manipulate_a', 'look_down_a', 'pickup_object_a',
        'object_template_a', 'look_down_m', 'pickup_object_m', 'finished', 'failed']
    sections = text(spec)
    assert sections['env_init'][:2] == ['stand_prep_c', '!stand_prep_f']
    assert '!stand_c' in sections['env_init']
    assert sections['sys_init'][:6] == ['!stand_prep_a', '!stand_a', '!manipulate_a', '!look_down_a',
                                        '!pickup_object_a', '!object_template_a']
    assert '!object_template_c | !manipulate_c -> !pickup_object_a' in sections['sys_trans']
    assert '!stand_c -> !look_down_a' in sections['sys_trans']
    assert 'look_down_a & next(look_down_c) | look_down_m <-> next(look_down_m)' in sections['sys_trans']
    assert ('pickup_object_a & next(pickup_object_c) & look_down_m | pickup_object_m <-> next(pickup_object_m)'
            in sections['sys_trans'])
    assert 'finished <-> look_down_m & pickup_object_m' in sections['sys_trans']
    assert ('failed <-> stand_prep_f | stand_f | manipulate_f | look_down_f | pickup_object_f'
            ' | object_template_f') in sections['sys_trans']
    assert sections['sys_liveness'] == ['finished | failed']
    # One fairness condition for all modes (13), one per action (7).
    assert len(sections['env_liveness']) == 1 + 3
    # Modes that the task does not need are not in the specification.
    assert not any(name.startswith(('walk', 'step', 'footstep')) for name in spec.propositions())


def test_paper_demo_footstep_execution_from_manipulate():
    spec = compile_task(robot_system('atlas'), ['manipulate'], ['footstep_execution'])
    p = spec.provenance.pertinence
    assert p.modes == ('stand', 'manipulate')
    assert p.actions == ('footstep_execution', 'footstep_plan', 'footstep_goal', 'target_pose')
    sections = text(spec)
    assert 'manipulate_c' in sections['env_init'] and '!stand_c' in sections['env_init']
    assert '!footstep_plan_c | !stand_c -> !footstep_execution_a' in sections['sys_trans']
    assert '!target_pose_c -> !footstep_goal_a' in sections['sys_trans']
    # target_pose has no preconditions: no (8) formula mentions it as the action.
    assert not any(f.endswith('-> !target_pose_a') for f in sections['sys_trans'])


@pytest.mark.parametrize('goal, modes', [
    ('walk', ('stand_prep', 'stand', 'walk')),
    ('step', ('stand_prep', 'stand', 'step')),
])
def test_locomotion_mode_goals_bring_in_their_path(goal, modes):
    spec = compile_task(robot_system('atlas'), ['stand_prep'], [goal])
    assert spec.provenance.pertinence.modes == modes
    assert spec.provenance.pertinence.reasons['stand'] == f'on the way from stand_prep to {goal}'
    assert f'{goal}_a & next({goal}_c) | {goal}_m <-> next({goal}_m)' in text(spec)['sys_trans']


def test_mode_topology_is_restricted_to_pertinent_modes_with_self_loops():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['walk'])
    assert ('next(stand_c) -> next(stand_a & !stand_prep_a & !walk_a) | next(walk_a & !stand_prep_a & !stand_a)'
            ' | next(!stand_prep_a & !stand_a & !walk_a)') in text(spec)['sys_trans']


def test_walking_between_two_manipulation_goals_keeps_every_needed_mode():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['pickup_object', 'walk', 'grasp_object'])
    assert spec.provenance.pertinence.modes == ('stand_prep', 'stand', 'manipulate', 'walk')


def test_unreachable_mode_goal_is_rejected():
    with pytest.raises(InvalidGoalsError) as caught:
        compile_task(robot_system('atlas'), ['stand'], ['stand_prep'])
    assert caught.value.item == 'stand_prep' and caught.value.code == 'INVALID_GOALS'
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in str(caught.value)
    assert 'can only change to manipulate, step, walk' in str(caught.value)


def test_shortest_paths_leave_detours_out():
    robot = abstraction_from_dict({
        'control_modes': {'a': ['b', 'x'], 'b': ['c'], 'x': ['y'], 'y': ['c'], 'c': ['a']},
        'actions': {'work': ['c']}})
    p = infer_pertinence(robot, 'a', ['a'], ['work'])
    assert p.modes == ('a', 'b', 'c')
    assert p.reasons == {'a': 'initial mode', 'b': 'on the way from a to c',
                         'c': 'precondition of work', 'work': 'goal 1'}


# --- variants -----------------------------------------------------------------------------------

def test_unordered_goals_use_eq17():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'], strict_order=False)
    sys_trans = text(spec)['sys_trans']
    assert 'next(look_down_c) | look_down_m <-> next(look_down_m)' in sys_trans
    assert 'next(pickup_object_c) | pickup_object_m <-> next(pickup_object_m)' in sys_trans
    assert not any('look_down_m | pickup_object_m' in f for f in sys_trans)


def test_unordered_goal_order_does_not_change_propositions():
    one = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'], strict_order=False)
    other = compile_task(robot_system('atlas'), ['stand_prep'], ['pickup_object', 'look_down'], strict_order=False)
    assert one.env_props == other.env_props
    assert one.env_trans == other.env_trans


def test_retry_after_failure_encoding():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down'], sm_outcomes=['finished'])
    sections = text(spec)
    assert 'failed' not in spec.sys_props and spec.sys_props[-1] == 'finished'
    assert sections['sys_liveness'] == ['finished']
    # Deactivation is required after completion only, so keeping π_a on after failure retries.
    assert 'look_down_a & next(look_down_c) -> next(!look_down_a)' in sections['sys_trans']
    assert 'look_down_a & next(look_down_f) -> next(!look_down_a)' not in sections['sys_trans']
    assert '!look_down_a | next(look_down_c)' in sections['env_liveness']
    assert ('stand_prep_a & !stand_a & next(stand_prep_c) | stand_a & !stand_prep_a & next(stand_c)'
            ' | !stand_prep_a & !stand_a') in sections['env_liveness']
    assert not any('failed' in f for f in sections['sys_trans'])


def test_sm_outcomes_order_is_normalized():
    assert compile_task(robot_system('atlas'),
                        'stand_prep', 'walk', sm_outcomes=['failed', 'finished']).sys_props[-2:] == \
        ['finished', 'failed']


def test_default_initial_mode_and_action_initial_condition():
    spec = compile_task(robot_system('atlas'), ['object_template'], ['pickup_object'])
    assert spec.provenance.pertinence.initial_mode == 'stand_prep'
    env_init = text(spec)['env_init']
    assert 'stand_prep_c' in env_init and 'object_template_c' in env_init and '!object_template_f' in env_init


def test_initial_condition_not_needed_is_left_out_and_explained():
    spec = compile_task(robot_system('atlas'), 'stand_prep,target_pose', 'walk')
    assert 'target_pose_c' not in spec.env_props
    assert spec.provenance.pertinence.left_out == {'target_pose': 'initial condition not needed by any goal'}
    assert 'Left out: target_pose' in explain(spec)


def test_comma_separated_strings_are_accepted():
    assert compile_task(robot_system('atlas'), 'stand_prep', 'look_down, pickup_object') == \
        compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'])


def test_explain_lists_items_and_reasons():
    summary = compile_task(robot_system('atlas'), ['manipulate'], ['footstep_execution']).explain()
    assert 'Control modes: stand (precondition of footstep_execution), manipulate (initial mode).' in summary
    assert 'target_pose (precondition of footstep_goal)' in summary
    assert 'Size: ' in summary


def test_mobile_manipulator_compiles_a_task():
    spec = compile_task(robot_system('mobile_manipulator'), [], ['grasp', 'place'])
    p = spec.provenance.pertinence
    assert p.initial_mode == 'parked'
    assert text(spec)['env_init'][:2] == ['parked_c', '!parked_f']
    assert p.modes == ('parked', 'driving', 'manipulating')
    assert p.actions == ('localize', 'navigate', 'detect_object', 'plan_grasp', 'grasp', 'place')
    assert '!plan_grasp_c | !manipulating_c -> !grasp_a' in text(spec)['sys_trans']
    assert spec.undeclared_variables() == []


def test_configurable_outcomes(tmp_path):
    (tmp_path / 'beeper.yaml').write_text(yaml.safe_dump({'abstraction': {
        'outcomes': ['completed', 'failed', 'preempted'],
        'control_modes': {'on': []}, 'initial_mode': 'on', 'actions': {'beep': ['on']}}}))
    spec = compile_task(robot_system('beeper', tmp_path), [], ['beep'])
    assert spec.env_props == ['on_c', 'on_f', 'on_p', 'beep_c', 'beep_f', 'beep_p']
    assert 'failed <-> on_f | on_p | beep_f | beep_p' in text(spec)['sys_trans']
    assert 'next(beep_p) -> next(!beep_c) & next(!beep_f)' in text(spec)['env_trans']


def test_system_without_control_modes(tmp_path):
    (tmp_path / 'speaker.yaml').write_text('abstraction:\n  actions: {say_hello: []}\n')
    spec = compile_task(robot_system('speaker', tmp_path), [], ['say_hello'])
    assert spec.env_props == ['say_hello_c', 'say_hello_f']
    assert spec.provenance.pertinence.modes == ()


def test_a_chain_of_thousands_of_preconditions_compiles(tmp_path):
    actions = {f'act{i}': ['on'] if i == 0 else [f'act{i - 1}'] for i in range(3000)}
    (tmp_path / 'chain.yaml').write_text(yaml.safe_dump({'abstraction': {
        'control_modes': {'on': []}, 'initial_mode': 'on', 'actions': actions}}, sort_keys=False))
    spec = compile_task(robot_system('chain', tmp_path), [], ['act2999'])
    assert spec.provenance.pertinence.actions == tuple(actions)
    assert spec.provenance.pertinence.reasons['act0'] == 'precondition of act1'


# --- determinism --------------------------------------------------------------------------------

def test_same_request_gives_byte_identical_output():
    request = dict(system=robot_system('atlas'), initial_conditions=['stand_prep'],
                   goals=['look_down', 'pickup_object'])
    first, second = compile_task(**request), compile_task(**request)
    assert first.to_structuredslugs() == second.to_structuredslugs()
    assert first.to_slugsin() == second.to_slugsin()
    assert first.to_text_sections() == second.to_text_sections()


def test_shared_preconditions_are_not_duplicated():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['pickup_object', 'grasp_object'])
    for section in ('env_trans', 'sys_trans', 'env_liveness', 'env_init', 'sys_init'):
        formulas = text(spec)[section]
        assert len(formulas) == len(set(formulas)), section
    assert spec.env_props.count('object_template_c') == 1


# --- custom LTL ---------------------------------------------------------------------------------

def test_custom_ltl_is_merged_and_pulls_in_what_it_mentions():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down'], custom_ltl={
        'sys_props': ['beacon'],
        'sys_trans': ['next(beacon) <-> next(look_down_a)', '!approach_object_a'],
        'env_trans': ['obj_detected -> next(obj_detected)'],
    })
    sections = text(spec)
    assert sections['sys_trans'][-2:] == ['next(beacon) <-> next(look_down_a)', '!approach_object_a']
    assert sections['env_trans'][-1] == 'obj_detected -> next(obj_detected)'
    assert 'beacon' in spec.sys_props and 'obj_detected' in spec.env_props
    p = spec.provenance.pertinence
    assert 'approach_object' in p.actions and 'object_template' in p.actions
    assert p.reasons['approach_object'] == 'mentioned in custom LTL'
    assert spec.provenance.custom_sections == ('sys_props', 'env_trans', 'sys_trans')


def test_custom_ltl_may_use_goal_memories_and_sm_outcomes():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down'],
                        custom_ltl={'sys_trans': ['look_down_m -> !failed']})
    assert text(spec)['sys_trans'][-1] == 'look_down_m -> !failed'


# --- bad input ----------------------------------------------------------------------------------

def raised(error_type, **overrides) -> SpecificationError:
    """The error compiling a request gives, its system read by name as the edges read it."""
    request = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down'])
    request.update(overrides)
    name, config_dir = request.pop('system'), request.pop('config_dir', None)
    with pytest.raises(error_type) as caught:
        with task_system_errors():
            system = robot_system(name, config_dir)
        compile_task(system, **request)
    assert isinstance(caught.value, SpecificationError)
    return caught.value


def test_unknown_system():
    error = raised(UnknownSystemError, system='marsrover')
    assert error.item == 'marsrover' and error.code == 'UNKNOWN_SYSTEM'


def test_unknown_goal():
    error = raised(UnknownPropositionError, goals=['look_down', 'dance'])
    assert error.item == 'dance' and error.code == 'UNKNOWN_PROPOSITION' and 'unknown goal' in str(error)


def test_unknown_initial_condition():
    error = raised(UnknownPropositionError, initial_conditions=['sitting'])
    assert error.item == 'sitting' and error.code == 'UNKNOWN_PROPOSITION'


def test_two_control_modes_as_initial_conditions():
    error = raised(InvalidInitialConditionsError, initial_conditions=['stand_prep', 'stand'])
    assert error.item == 'stand' and 'one control mode' in str(error)


def test_no_initial_mode_and_no_default(tmp_path):
    (tmp_path / 'nodefault.yaml').write_text(textwrap.dedent('''\
        abstraction:
          control_modes: {up: [down], down: [up]}
          actions: {wave: [up]}
        '''))
    error = raised(InvalidInitialConditionsError, system='nodefault', initial_conditions=[],
                   goals=['wave'], config_dir=tmp_path)
    assert 'no initial control mode' in str(error)


def test_empty_goals():
    error = raised(InvalidGoalsError, goals=[])
    assert error.code == 'INVALID_GOALS' and 'no goals' in str(error)


def test_goals_of_the_wrong_type():
    assert raised(InvalidGoalsError, goals=42).item == '42'
    assert raised(InvalidGoalsError, goals=['look_down', None]).item == 'None'


def test_repeated_goal():
    assert raised(InvalidGoalsError, goals=['look_down', 'look_down']).item == 'look_down'


@pytest.mark.parametrize('sm_outcomes, item', [
    (['failed'], 'failed'),
    (['finished', 'aborted'], 'aborted'),
    ([], ''),
    (['finished', 'finished'], 'finished,finished'),
])
def test_unsupported_sm_outcomes(sm_outcomes, item):
    error = raised(InvalidSmOutcomesError, sm_outcomes=sm_outcomes)
    assert error.item == item and error.code == 'INVALID_SM_OUTCOMES'


def test_malformed_custom_formula():
    error = raised(InvalidFormulaError, custom_ltl={'sys_trans': ['look_down_a & & stand_a']})
    assert error.item == 'look_down_a & & stand_a' and error.code == 'INVALID_FORMULA'


def test_custom_formula_naming_unknown_proposition():
    error = raised(UnknownPropositionError, custom_ltl={'sys_trans': ['next(teleport_a) -> stand_c']})
    assert error.item == 'teleport_a' and error.code == 'UNKNOWN_PROPOSITION'


def test_custom_formula_naming_memory_of_a_non_goal():
    assert raised(UnknownPropositionError, custom_ltl={'sys_trans': ['!walk_m']}).item == 'walk_m'


def test_custom_formula_in_the_wrong_section():
    error = raised(InvalidFormulaError, custom_ltl={'env_trans': ['next(look_down_a) -> next(stand_c)']})
    assert error.item == 'next(look_down_a) -> next(stand_c)'


def test_custom_ltl_unknown_section():
    assert raised(InvalidFormulaError, custom_ltl={'sys_safety': ['stand_c']}).item == 'sys_safety'


def test_custom_ltl_redeclaring_an_output_as_input():
    assert raised(InvalidFormulaError, custom_ltl={'env_props': ['finished']}).item == 'finished'


def test_invalid_abstraction(tmp_path):
    (tmp_path / 'broken.yaml').write_text('abstraction:\n  actions: {grab: [hand]}\n')
    error = raised(InvalidAbstractionError, system='broken', goals=['grab'], config_dir=tmp_path)
    assert error.item == 'hand' and error.code == 'ABSTRACTION_CONFIG_INVALID'


def test_missing_abstraction_section(tmp_path):
    (tmp_path / 'bare.yaml').write_text('flexbe: {}\n')
    assert raised(InvalidAbstractionError, system='bare', config_dir=tmp_path).item == 'abstraction'


# --- properties over many tasks -------------------------------------------------------------------

ATLAS_GOALS = ['stand', 'manipulate', 'step', 'walk', 'look_down', 'pickup_object', 'grasp_object',
               'pregrasp', 'approach_object', 'footstep_execution', 'target_pose']


@settings(max_examples=40, deadline=None)
@given(goals=st.lists(st.sampled_from(ATLAS_GOALS), min_size=1, max_size=4, unique=True),
       strict=st.booleans(), retry=st.booleans())
def test_every_task_is_well_formed_and_deterministic(goals, strict, retry):
    sm_outcomes = ['finished'] if retry else ['finished', 'failed']
    spec = compile_task(robot_system('atlas'), ['stand_prep'], goals, sm_outcomes=sm_outcomes, strict_order=strict)
    assert spec.undeclared_variables() == []
    assert len(set(spec.propositions())) == len(spec.propositions())
    for section, formulas in text(spec).items():
        assert len(formulas) == len(set(formulas)), section
    assert [f'{g}_m' for g in goals] == [p for p in spec.sys_props if p.endswith('_m')]
    p = spec.provenance.pertinence
    assert 'stand_prep' in p.modes and set(goals) <= set(p.modes) | set(p.actions)
    again = compile_task(robot_system('atlas'), ['stand_prep'], goals, sm_outcomes=sm_outcomes, strict_order=strict)
    assert again.to_slugsin() == spec.to_slugsin()


def test_misspelled_goal_and_initial_condition_suggest_the_close_name():
    with pytest.raises(UnknownPropositionError) as caught:
        compile_task(robot_system('atlas'), ['stand'], ['look_dwon'])
    assert caught.value.code == 'UNKNOWN_PROPOSITION' and caught.value.item == 'look_dwon'
    assert 'did you mean look_down?' in str(caught.value)
    with pytest.raises(UnknownPropositionError) as caught:
        compile_task(robot_system('atlas'), ['stnad'], ['look_down'])
    assert 'did you mean stand?' in str(caught.value)
    with pytest.raises(UnknownPropositionError) as caught:
        compile_task(robot_system('atlas'), ['stand'], ['xyzzy'])
    assert 'did you mean' not in str(caught.value)
