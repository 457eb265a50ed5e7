"""One diagnosis whichever stage finds the impossibility (issue 33 item 1), ROS-free: the compiler's
refusal carries the diagnosis synthesis would give, the play is told in the state machine's
terms, the synthesizer's own play is left out, and a specification without provenance is
diagnosed by its formulas."""

import pytest

from ltl_specification import compile_task
from ltl_specification.diagnosis import diagnose, explain_unsynthesizable, goal_findings
from ltl_specification.errors import ImpossibleGoalsError, InvalidGoalsError
from ltl_synthesizer.explanation import without_play
from ltl_synthesizer.synthesizer import synthesize
from respec.parsing import spec_from_text_sections
from respec.robot import robot_system


def test_the_refusal_carries_the_diagnosis_that_synthesis_gives_from_the_other_start():
    with pytest.raises(ImpossibleGoalsError) as refused:
        compile_task(robot_system('atlas'), ['stand'], ['look_down', 'stand_prep'])
    refusal = refused.value.diagnosis
    assert refused.value.code == 'INVALID_GOALS' and refused.value.item == 'stand_prep'
    assert str(refused.value) == refusal.message()
    # the same sentence as the form's check, and as the synthesis stage's diagnosis from stand_prep
    unrealizable = diagnose(compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'stand_prep']))
    assert refusal.sentence == goal_findings(robot_system('atlas'), ['stand'], ['look_down', 'stand_prep'])[0].sentence
    assert refusal.sentence == unrealizable.sentence
    assert {entry.name() for entry in refusal.core} >= {'eq. (9) control-mode topology for stand',
                                                        'eq. (20) goals in the given order for stand_prep'}
    assert refusal.play[0] == 'start: stand returns changed (now in stand)'
    assert 'state look_down (TiltHeadState) starts' in refusal.play
    assert 'state stand (ChangeControlModeActionState) starts' in unrealizable.play


def test_in_any_order_the_refusal_leads_with_the_any_order_sentence():
    with pytest.raises(ImpossibleGoalsError) as refused:
        compile_task(robot_system('atlas'), ['stand'], ['look_down', 'stand_prep'], strict_order=False)
    assert str(refused.value).startswith('Goal 2 (stand_prep) can never be achieved: the robot starts in stand,')
    assert 'How the environment wins' in str(refused.value)


def test_a_refusal_without_explanation_is_the_sentence_alone_and_immediate():
    with pytest.raises(ImpossibleGoalsError) as refused:
        compile_task(robot_system('atlas'), ['step'], ['stand_prep', 'pregrasp'], explain_refusal=False)
    assert str(refused.value) == goal_findings(robot_system('atlas'), ['step'], ['stand_prep', 'pregrasp'])[0].sentence
    assert refused.value.diagnosis.core == [] and refused.value.diagnosis.play == []


def test_a_mode_only_custom_ltl_needs_is_refused_with_its_own_sentence_and_the_diagnosis():
    with pytest.raises(InvalidGoalsError) as refused:
        compile_task(robot_system('atlas'), ['stand'], ['look_down'], custom_ltl={'sys_trans': ['!stand_prep_a']})
    first_line = str(refused.value).splitlines()[0]
    assert first_line == ("Control mode 'stand_prep' (mentioned in custom LTL) cannot be reached from the "
                          "initial mode 'stand' on atlas.")
    assert refused.value.item == 'stand_prep'


def test_the_synthesizers_play_is_left_out_once_the_diagnosis_tells_one():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'stand_prep'])
    details = synthesize(spec).explanation
    assert 'Environment play (counter-strategy' in details
    kept = without_play(details)
    assert 'Environment play' not in kept and 'step 0' not in kept and details.startswith(kept)
    message = explain_unsynthesizable(details, spec, spec.provenance)
    assert message.count('Environment play') == 0 and message.count('How the environment wins') == 1
    assert message.endswith(kept)
    assert without_play('no play here') == 'no play here'


def test_a_specification_without_provenance_is_diagnosed_by_its_formulas():
    spec = spec_from_text_sections({'env_props': ['x'], 'sys_props': ['y'],
                                    'sys_trans': ['next(y) <-> !next(x)'], 'sys_liveness': ['y'],
                                    'env_trans': [], 'env_liveness': [], 'env_init': [], 'sys_init': []})
    diagnosis = diagnose(spec)
    assert [entry.name() for entry in diagnosis.core] == ['formula sys_trans[0]', 'formula sys_liveness[0]']
    # x is an input no assumption mentions, which the core reads: the sentence names it (issue 45).
    assert diagnosis.sentence.startswith("The task needs the sensor 'x'")
    assert 'sys_trans[0]: next(y) <-> !next(x)' in diagnosis.sentence
    assert diagnosis.play and diagnosis.play[0].startswith('start:')
    constrained = spec_from_text_sections({'env_props': ['x'], 'sys_props': ['y'],
                                           'sys_trans': ['next(y) <-> !next(x)'], 'sys_liveness': ['y'],
                                           'env_trans': ["x -> next(x)"], 'env_liveness': [], 'env_init': ['x'],
                                           'sys_init': []})
    assert diagnose(constrained).sentence.startswith('The task cannot be done as requested')
