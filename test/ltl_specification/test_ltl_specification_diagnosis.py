"""Diagnosis of impossible tasks: pre-check, unrealizable cores (delta debugging), plays in words."""

import itertools
import json

import pytest

from ltl_specification import compile_task
from ltl_specification.diagnosis import (diagnose, explain_unsynthesizable, goal_findings, impossible_next_goals,
                                        precheck)
from ltl_specification.provenance import provenance_from_json, provenance_to_json
from ltl_synthesizer import Limits
from ltl_synthesizer.unrealizable_core import (ddmin, droppable_sections, environment_play, is_realizable,
                                               restrict_guarantees, unrealizable_core)
from respec.parsing import spec_from_text_sections
from respec.spec import FORMULA_SECTIONS
from respec.robot import robot_system

IMPOSSIBLE = dict(system=robot_system('atlas'), initial_conditions=[], goals=['look_down', 'stand_prep'])


def test_formula_groups_cover_every_formula_and_name_an_equation():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'],
                        custom_ltl={'sys_trans': ['!walk_a']})
    groups = spec.provenance.groups
    covered = {(g.section, f) for g in groups for f in g.formulas}
    assert all((section, f) in covered for section in FORMULA_SECTIONS for f in getattr(spec, section))
    equations = {g.equation for g in groups}
    assert {'(3)', '(4)', '(5)', '(6)', '(7)', '(8)', '(9)', '(10)', '(11)', '(12)', '(13)', '(14)', '(15)',
            '(16)', '(20)', '(18a)', '(18b)', '(18c)', '(19)', 'custom'} <= equations
    topology = [g for g in groups if g.equation == '(9)']
    assert [g.item for g in topology] == ['stand_prep', 'stand', 'manipulate', 'walk']  # walk: custom LTL


def test_precheck_names_the_missing_transition():
    findings = precheck(compile_task(**IMPOSSIBLE))
    assert len(findings) == 1
    sentence = findings[0].sentence
    assert sentence.startswith('Goal 2 (stand_prep) can never be achieved')
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in sentence
    assert findings[0].config_item == 'control_modes.stand in config/atlas.yaml'


def test_precheck_accepts_possible_orders_and_unordered_goals():
    assert precheck(compile_task(robot_system('atlas'), [], ['stand_prep', 'look_down'])) == []
    assert precheck(compile_task(robot_system('atlas'), [], ['look_down', 'stand_prep'], strict_order=False)) == []
    assert precheck(compile_task(robot_system('atlas'), [], ['walk', 'look_down', 'pickup_object'])) == []


def test_precheck_of_a_specification_given_whole_finds_nothing_to_check():
    # No provenance: nothing says which robot and request the formulas come from.
    spec = spec_from_text_sections({'sys_props': ['a'], 'sys_liveness': ['a']})
    assert precheck(spec) == []


def test_precheck_names_forbidden_preconditions_and_contradictory_custom_ltl():
    forbidden = precheck(compile_task(robot_system('atlas'), [], ['look_down'], custom_ltl={'sys_trans': ['!stand_a']}))
    assert [f.item for f in forbidden] == ['stand']
    assert "custom LTL sys_trans[0] '!stand_a' forbids ever activating it" in forbidden[0].sentence
    contradictory = precheck(compile_task(robot_system('atlas'), [], ['look_down'],
                                          custom_ltl={'sys_trans': ['look_down_a', '!look_down_a']}))
    assert any('contradict each other' in f.sentence for f in contradictory)
    against_init = precheck(compile_task(robot_system('atlas'),
                                         [], ['look_down'], custom_ltl={'sys_init': ['stand_a']}))
    assert any('generated initial conditions' in f.sentence for f in against_init)


def test_core_is_unrealizable_and_one_minimal():
    spec = compile_task(**IMPOSSIBLE)
    assert not is_realizable(spec)
    core = unrealizable_core(spec, spec.provenance.groups)
    assert not is_realizable(core.specification)
    sections = droppable_sections(True)
    for index in range(len(core.groups)):
        fewer = core.groups[:index] + core.groups[index + 1:]
        assert is_realizable(restrict_guarantees(spec, fewer, sections)), core.groups[index]
    names = {(g.equation, g.item) for g in core.groups}
    assert ('(9)', 'stand') in names and ('(20)', 'stand_prep') in names
    assert all(g.section in sections for g in core.groups)


def test_realizable_spec_has_no_core():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'])
    assert unrealizable_core(spec, spec.provenance.groups) is None
    assert diagnose(spec) is None


def test_ddmin_finds_a_one_minimal_failing_subset():
    def fails(items):  # two 1-minimal failing subsets: [3, 7] and [12]
        return {3, 7} <= set(items) or 12 in items

    assert ddmin(list(range(16)), fails) in ([3, 7], [12])
    assert ddmin([x for x in range(16) if x != 12], fails) == [3, 7]
    assert ddmin([x for x in range(16) if x != 3], fails) == [12]
    calls = []
    result = ddmin(list(range(8)), lambda items: calls.append(items) or set(items) == set(range(8)))
    assert result == list(range(8))


def test_environment_play_shows_how_far_the_robot_gets():
    spec = compile_task(**IMPOSSIBLE)
    steps = environment_play(spec, length=8)
    assert steps[0]['stand_prep_c'] == 1 and not any(s['stand_prep_m'] for s in steps)
    assert steps[-1]['look_down_m'] == 1  # the robot achieved goal 1, then it is stuck
    for before, after in itertools.pairwise(steps):
        assert None not in after.values()


def test_diagnosis_message_leads_with_the_plain_sentence():
    diagnosis = diagnose(compile_task(**IMPOSSIBLE))
    message = diagnosis.message()
    first_line = message.splitlines()[0]
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in first_line
    assert 'eq. (9) control-mode topology for stand (control_modes.stand in config/atlas.yaml: ' \
           'stand -> manipulate, step, walk)' in message
    assert 'goal look_down achieved' in message and 'now in stand' in message


def test_core_sentence_when_the_precheck_finds_nothing():
    # Contradiction only visible over time: look_down must never be activated after stand completes.
    spec = compile_task(robot_system('atlas'), [], ['look_down'], custom_ltl={'sys_trans': ['stand_c -> !look_down_a']})
    assert precheck(spec) == []
    diagnosis = diagnose(spec)
    assert diagnosis.sentence.startswith('The task cannot be done as requested')
    assert "custom LTL sys_trans[0]" in diagnosis.sentence


def test_explain_unsynthesizable_keeps_the_details_and_never_raises():
    impossible = compile_task(**IMPOSSIBLE)
    message = explain_unsynthesizable('DETAILS', impossible, impossible.provenance)
    assert message.splitlines()[0].startswith('Goal 2 (stand_prep)') and message.endswith('DETAILS')
    # without a provenance (a specification given whole): diagnosed by its formulas (issue 33)
    given_whole = spec_from_text_sections(impossible.to_text_sections())
    by_formulas = explain_unsynthesizable('DETAILS', given_whole, None)
    assert by_formulas.startswith('The task cannot be done as requested') and by_formulas.endswith('DETAILS')
    realizable = compile_task(robot_system('atlas'), [], ['look_down'])
    assert explain_unsynthesizable('DETAILS', realizable, realizable.provenance) == 'DETAILS'


@pytest.mark.parametrize('task', [IMPOSSIBLE, dict(system=robot_system('atlas'), initial_conditions=[],
                                                   goals=['look_down'],
                                                   custom_ltl={'sys_trans': ['stand_c -> !look_down_a']})])
def test_a_specification_sent_with_its_provenance_as_json_is_diagnosed_the_same(task):
    """What the synthesis node receives: the specification as message sections and the
    provenance as JSON, with no robot configuration at hand."""
    compiled = compile_task(**task)
    text = provenance_to_json(compiled.provenance)
    assert text == provenance_to_json(compile_task(**task).provenance)  # deterministic
    received = provenance_from_json(text)
    assert provenance_to_json(received) == text
    sent = spec_from_text_sections(compiled.to_text_sections())
    assert diagnose(sent, provenance=received).message() == diagnose(compiled).message()
    bad_formula = json.loads(text)
    bad_formula['groups'][0][5] = ['((']
    for malformed in ('{"format": 0}', '[]', 'not json', json.dumps(bad_formula)):
        with pytest.raises(ValueError):
            provenance_from_json(malformed)


def test_deadline_keeps_the_precheck_sentence():
    diagnosis = diagnose(compile_task(**IMPOSSIBLE), limits=Limits(deadline=0.0))
    assert 'stand -> stand_prep' in diagnosis.sentence and 'not computed' in diagnosis.note


def test_goal_findings_and_impossible_next_goals_without_compiling():
    assert [f.item for f in goal_findings(robot_system('atlas'), [], ['look_down', 'stand_prep'])] == ['stand_prep']
    assert goal_findings(robot_system('atlas'), [], ['look_down', 'stand_prep'], strict_order=False) == []
    assert goal_findings(robot_system('atlas'), ['walk'], ['stand_prep'], strict_order=False)[0].sentence.startswith(
        'Goal 1 (stand_prep) can never be achieved: the robot starts in walk, and walk -> stand_prep')
    assert goal_findings(robot_system('atlas'), [], ['no_such_goal']) == []
    impossible = impossible_next_goals(robot_system('atlas'), [], ['look_down'])
    assert list(impossible) == ['stand_prep']
    assert 'stand -> stand_prep is not a transition' in impossible['stand_prep']
    assert impossible_next_goals(robot_system('atlas'), [], []) == {}
