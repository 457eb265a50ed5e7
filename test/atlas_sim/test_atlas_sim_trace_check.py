"""The trace checker on hand-made traces: good runs pass, each kind of violation is reported."""

import json

import pytest

from atlas_sim.executive.trace_check import (OutcomeTracker, Trace, TraceError, TraceStep, check_trace,
                                   least_violating_assignments, partial_evaluate, valuations_of_trace)
from ltl_specification import compile_task
from respec.ltl import to_infix, var
from respec.parsing import parse_formula
from respec.robot import robot_system

MODES = ['stand_prep', 'stand', 'manipulate', 'step', 'walk']


def make_trace(steps, outcome, initial_mode='stand_prep', completed=()):
    """A trace from (state, capabilities, reports) triples, outcomes tracked as the executor does.

    ``reports`` are (capability, outcome) pairs reported while the state ran; a report for a
    capability the state does not activate stands for a robot misbehaving.
    """
    tracker = OutcomeTracker(MODES, initial_mode, completed)
    trace = Trace(outcome=outcome)
    for index, (state, capabilities, reports) in enumerate(steps):
        step = TraceStep(index=index, state=state, capabilities=list(capabilities),
                         activated=sorted(f'{c}_a' for c in capabilities),
                         outcomes_at_entry=tracker.true_propositions(), mode_at_entry=tracker.mode)
        tracker.activate(capabilities)
        for capability, result in reports:
            tracker.report(capability, result)
            step.results.append({'capability': capability, 'outcome': result, 'reason': '', 'time': 0.0,
                                 'abandoned': capability not in capabilities})
        step.outcomes_at_exit, step.mode_at_exit = tracker.true_propositions(), tracker.mode
        trace.steps.append(step)
    for step, following in zip(trace.steps, trace.steps[1:]):
        step.transition = following.state.lstrip('/')
    if trace.steps and outcome:
        trace.steps[-1].transition = outcome
    return trace


@pytest.fixture(scope='module')
def walk_spec():
    return compile_task(robot_system('atlas'), ['stand_prep'], ['walk'], sm_outcomes=['finished', 'failed'])


@pytest.fixture(scope='module')
def pickup_spec():
    return compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'])


@pytest.fixture(scope='module')
def unordered_pickup_spec():
    return compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'], strict_order=False)


GOOD_WALK = [('/stand', ['stand'], [('stand', 'completed')]),
             ('/walk', ['walk'], [('walk', 'completed')])]

PICKUP_IN_ORDER = [('/object_template', ['object_template'], [('object_template', 'completed')]),
                   ('/stand', ['stand'], [('stand', 'completed')]),
                   ('/look_down', ['look_down'], [('look_down', 'completed')]),
                   ('/manipulate', ['manipulate'], [('manipulate', 'completed')]),
                   ('/pickup_object', ['pickup_object'], [('pickup_object', 'completed')])]

PICKUP_OUT_OF_ORDER = [('/object_template', ['object_template'], [('object_template', 'completed')]),
                       ('/stand', ['stand'], [('stand', 'completed')]),
                       ('/manipulate', ['manipulate'], [('manipulate', 'completed')]),
                       ('/pickup_object', ['pickup_object'], [('pickup_object', 'completed')]),
                       ('/stand_1', ['stand'], [('stand', 'completed')]),
                       ('/look_down', ['look_down'], [('look_down', 'completed')])]


def kinds(report):
    return [v.kind for v in report.violations]


# --- good runs ----------------------------------------------------------------------------------

def test_a_good_run_passes_and_counts_the_goal(walk_spec):
    report = check_trace(make_trace(GOOD_WALK, 'finished'), walk_spec)
    assert report.ok, report.summary()
    assert report.goals == ['walk'] and report.goals_completed_at == {'walk': 1}
    assert report.positions == 4  # start, /stand, /walk, finished


def test_a_good_failing_run_passes(walk_spec):
    steps = [('/stand', ['stand'], [('stand', 'completed')]), ('/walk', ['walk'], [('walk', 'failed')])]
    report = check_trace(make_trace(steps, 'failed'), walk_spec)
    assert report.ok, report.summary()
    assert report.goals_completed_at == {'walk': None}


def test_ordered_goals_in_order_pass(pickup_spec):
    report = check_trace(make_trace(PICKUP_IN_ORDER, 'finished'), pickup_spec)
    assert report.ok, report.summary()
    assert report.goals_completed_at == {'look_down': 2, 'pickup_object': 4}


def test_a_broken_off_run_is_checked_up_to_where_it_stopped(walk_spec):
    report = check_trace(make_trace(GOOD_WALK[:1], None), walk_spec)
    assert report.ok and report.positions == 2  # start, /stand (still running)


# --- violations -----------------------------------------------------------------------------------

def test_env_init_violation_when_the_robot_starts_elsewhere(walk_spec):
    report = check_trace(make_trace(GOOD_WALK[1:], 'finished', initial_mode='stand'), walk_spec)
    env_init = [v for v in report.violations if v.kind == 'env_init']
    assert env_init and 'stand_prep_c' in env_init[0].formulas
    assert env_init[0].transition == 'start'


def test_env_trans_violation_when_the_mode_changes_without_activation(walk_spec):
    # The robot reports a finished walk transition while the machine only activated stand.
    steps = [('/stand', ['stand'], [('stand', 'completed'), ('walk', 'completed')]),
             ('/walk', ['walk'], [('walk', 'completed')])]
    report = check_trace(make_trace(steps, 'finished'), walk_spec)
    violation = next(v for v in report.violations if v.kind == 'env_trans')
    assert violation.step == 0 and violation.transition == '/stand -> /walk'
    # eq. (11): from stand_prep, activating stand may only lead to stand_prep, stand_c or stand_f
    assert 'stand_prep_c & stand_a & !stand_prep_a & !walk_a -> next(stand_prep_c) | next(stand_c) | ' \
           'next(stand_f)' in violation.formulas


def test_env_trans_violation_when_an_outcome_changes_without_activation(pickup_spec):
    steps = list(PICKUP_IN_ORDER)
    steps[1] = ('/stand', ['stand'], [('stand', 'completed'), ('look_down', 'failed')])
    report = check_trace(make_trace(steps, 'finished'), pickup_spec)
    violation = next(v for v in report.violations if v.kind == 'env_trans')
    assert violation.step == 1
    assert '!look_down_f & !look_down_a -> next(!look_down_f)' in violation.formulas  # eq. (5)


def test_sys_trans_violation_for_a_forbidden_mode_transition(walk_spec):
    steps = [('/walk', ['walk'], [('walk', 'failed')])]  # stand_prep -> walk is not allowed
    report = check_trace(make_trace(steps, 'failed'), walk_spec)
    violation = next(v for v in report.violations if v.kind == 'sys_trans')
    assert violation.transition == 'start -> /walk'
    assert any(f.startswith('next(stand_prep_c) -> ') for f in violation.formulas)  # eq. (9)


def test_sys_trans_violation_for_an_unmet_precondition(pickup_spec):
    steps = [PICKUP_IN_ORDER[0], ('/look_down', ['look_down'], [('look_down', 'failed')])]
    report = check_trace(make_trace(steps, 'failed'), pickup_spec)
    violation = next(v for v in report.violations if v.kind == 'sys_trans')
    assert violation.step == 0 and violation.transition == '/object_template -> /look_down'
    assert violation.formulas == ['!stand_c -> !look_down_a']  # eq. (8)


def test_reactivating_after_completion_is_fine_through_an_idle_step(pickup_spec):
    # eq. (3) forbids keeping an activation on after its outcome, but the automaton may pass
    # through a state that activates nothing (which the generated machine skips) and activate again.
    steps = list(PICKUP_IN_ORDER)
    steps.insert(1, ('/object_template_again', ['object_template'], [('object_template', 'completed')]))
    report = check_trace(make_trace(steps, 'finished'), pickup_spec)
    assert report.ok, report.summary()


def test_sys_trans_violation_for_going_on_after_a_failure(walk_spec):
    # With outcomes finished/failed the machine must end in 'failed' once stand failed (eq. (18b)).
    steps = [('/stand', ['stand'], [('stand', 'failed')]), ('/stand_1', ['stand'], [('stand', 'completed')]),
             ('/walk', ['walk'], [('walk', 'completed')])]
    report = check_trace(make_trace(steps, 'finished'), walk_spec)
    violation = next(v for v in report.violations if v.kind == 'sys_trans')
    assert violation.step == 0
    assert 'failed <-> stand_prep_f | stand_f | walk_f' in violation.formulas


def test_finishing_without_the_goal_violates_the_spec_and_the_goal_check(walk_spec):
    report = check_trace(make_trace(GOOD_WALK[:1], 'finished'), walk_spec)
    assert set(kinds(report)) == {'sys_trans', 'goal_order'}
    sys_violation = next(v for v in report.violations if v.kind == 'sys_trans')
    assert sys_violation.transition == '/stand -> finished'
    assert 'finished <-> walk_m' in sys_violation.formulas  # eq. (18a)
    goal_violation = next(v for v in report.violations if v.kind == 'goal_order')
    assert 'walk' in goal_violation.message


def test_goals_out_of_order_do_not_count_when_the_order_is_strict(pickup_spec):
    report = check_trace(make_trace(PICKUP_OUT_OF_ORDER, 'finished'), pickup_spec)
    assert report.goals_completed_at == {'look_down': 5, 'pickup_object': None}
    assert 'goal_order' in kinds(report) and 'sys_trans' in kinds(report)
    assert any('finished <-> look_down_m & pickup_object_m' in v.formulas for v in report.violations)


def test_goals_out_of_order_count_when_unordered(unordered_pickup_spec):
    report = check_trace(make_trace(PICKUP_OUT_OF_ORDER, 'finished'), unordered_pickup_spec, ordered=False)
    assert report.ok, report.summary()
    assert report.goals_completed_at == {'look_down': 5, 'pickup_object': 3}


def test_sys_init_violation_is_reported(walk_spec):
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['walk'])
    spec.sys_init.append(var('walk_a'))  # the start activates nothing
    report = check_trace(make_trace(GOOD_WALK, 'finished'), spec)
    violation = next(v for v in report.violations if v.kind == 'sys_init')
    assert violation.formulas == ['walk_a'] and violation.transition == 'start'


def test_the_check_recovers_after_a_violation_and_reports_later_ones(walk_spec):
    steps = [('/walk', ['walk'], [('walk', 'failed')]),                     # forbidden activation
             ('/stand', ['stand'], [('stand', 'completed'), ('walk', 'completed')])]  # robot misbehaves
    trace = make_trace(steps, None)
    trace.steps[-1].transition = 'walk'  # broke off after /stand ended
    report = check_trace(trace, walk_spec)
    found = [(v.kind, v.step, v.transition) for v in report.violations]
    assert found[0] == ('sys_trans', 0, 'start -> /walk')
    assert ('env_trans', 1, '/stand -> walk') in found


# --- malformed traces, helpers ------------------------------------------------------------------------

def test_inconsistent_consecutive_steps_are_rejected(walk_spec):
    trace = make_trace(GOOD_WALK, 'finished')
    trace.steps[1].outcomes_at_entry = ['stand_prep_c']
    with pytest.raises(TraceError) as error:
        check_trace(trace, walk_spec)
    assert error.value.item == '/walk'


def test_unknown_activation_and_outcome_are_rejected(walk_spec):
    trace = make_trace([('/look_down', ['look_down'], [])], None)
    with pytest.raises(TraceError) as error:
        check_trace(trace, walk_spec)
    assert error.value.item == 'look_down_a'
    with pytest.raises(TraceError) as error:
        check_trace(make_trace(GOOD_WALK, 'aborted'), walk_spec)
    assert error.value.item == 'aborted'


def test_trace_round_trips_through_json(pickup_spec):
    trace = make_trace(PICKUP_IN_ORDER, 'finished')
    again = Trace.from_dict(json.loads(json.dumps(trace.to_dict())))
    assert again == trace
    assert check_trace(again, pickup_spec).to_dict() == check_trace(trace, pickup_spec).to_dict()


def test_valuations_follow_activation_outcome_semantics(walk_spec):
    positions = valuations_of_trace(make_trace(GOOD_WALK, 'finished'), walk_spec)
    start, stand, walk, end = positions
    assert start['stand_prep_c'] and not start['stand_a'] and not start['finished']
    assert stand['stand_a'] and stand['stand_prep_c']
    assert walk['stand_c'] and not walk['stand_prep_c'] and walk['walk_a']
    assert end['walk_c'] and not end['stand_c'] and end['finished'] and not end['failed']
    assert 'walk_a' not in end  # the exit state's activations are not observed


def test_outcome_tracker_semantics():
    tracker = OutcomeTracker(MODES, 'stand', completed_actions=['object_template'],
                             sensors={'obj_detected': False})
    assert tracker.true_propositions() == ['object_template_c', 'stand_c']
    tracker.activate(['object_template', 'manipulate'])       # re-activation clears the outcome
    assert tracker.true_propositions() == ['stand_c']
    tracker.report('manipulate', 'failed')                    # failed transition: mode unchanged
    tracker.report('object_template', 'failed')
    tracker.read_sensors({'obj_detected': True})
    assert tracker.true_propositions() == ['manipulate_f', 'obj_detected', 'object_template_f', 'stand_c']
    tracker.activate(['manipulate'])
    tracker.report('manipulate', 'completed')
    assert tracker.true_propositions() == ['manipulate_c', 'obj_detected', 'object_template_f']


def test_partial_evaluation_is_kleene():
    formula = parse_formula('a & next(b) -> c')
    assert partial_evaluate(formula, {'a': False}, {}) is True       # false premise decides
    assert partial_evaluate(formula, {'a': True}, {}) is None
    assert partial_evaluate(formula, {'a': True, 'c': False}, {'b': True}) is False
    assert partial_evaluate(parse_formula('a <-> b'), {'a': True}, {}) is None


def test_least_violating_assignments_prunes_and_counts():
    formulas = [parse_formula('next(m) <-> a'), parse_formula('next(f) -> next(m)')]
    cost, found = least_violating_assignments(formulas, {'a': True}, {}, ['m', 'f'])
    assert cost == 0 and found == [{'m': True, 'f': False}, {'m': True, 'f': True}]
    cost, found = least_violating_assignments(formulas, {'a': False}, {'f': True}, ['m'])
    assert cost == 1 and len(found) == 2


# --- who broke what: the machine, the robot or the operator ------------------------------------

def forced_failure_of_look_down(following, outcome, forced=True):
    """object_template, stand, then look_down, on which the operator forced 'failed' before the
    robot reported anything, then ``following``."""
    trace = make_trace(PICKUP_IN_ORDER[:2] + [('/look_down', ['look_down'], [])] + following, outcome)
    if forced:
        trace.steps[2].forced, trace.steps[2].forced_propositions = 'failed', ['look_down_f']
    return trace


def test_a_machine_answering_a_forced_failure_is_not_blamed_and_a_broken_guarantee_is_named(pickup_spec):
    # The machine ends in 'failed' after the operator forced look_down's failure: it did right.
    assert check_trace(forced_failure_of_look_down([], 'failed'), pickup_spec).ok
    # The same run with nobody forcing anything: the machine ended in failed with nothing failed.
    report = check_trace(forced_failure_of_look_down([], 'failed', forced=False), pickup_spec)
    assert kinds(report) == ['sys_trans']
    guarantee = next(i for i, f in enumerate(pickup_spec.sys_trans, 1) if to_infix(f).startswith('failed <->'))
    assert report.violations[0].message == (
        'the state machine broke a guarantee of the specification (/look_down -> failed): '
        f'sys_trans {guarantee}: {to_infix(pickup_spec.sys_trans[guarantee - 1])}')
    assert report.violations[0].message in report.summary()


def test_a_forced_outcome_that_breaks_an_assumption_is_the_operators_by_name(pickup_spec):
    retrying = compile_task(robot_system('atlas'),
                            ['stand_prep'], ['look_down', 'pickup_object'], sm_outcomes=['finished'])
    following = [('/object_template_1', ['object_template'], [('object_template', 'completed')]),
                 ('/look_down_1', ['look_down'], [('look_down', 'completed')])]
    report = check_trace(forced_failure_of_look_down(following, None), retrying)
    assumption = next(i for i, f in enumerate(retrying.env_trans, 1)
                      if to_infix(f) == 'look_down_f & !look_down_a -> next(look_down_f)')
    assert kinds(report) == ['forced_outcome'] and report.violations[0].step == 3
    assert report.violations[0].message == (
        'the operator forced failed on look_down at step 2; the task assumed '
        f'env_trans {assumption}: look_down_f & !look_down_a -> next(look_down_f)')
    assert 'forced_outcome: the operator forced failed on look_down at step 2' in report.summary()
    # Forced on a state the trace says it has no such outcome for: the task assumed it never happens.
    trace = forced_failure_of_look_down([], 'failed')
    trace.steps[2].forced_propositions = ['look_down_x']
    report = check_trace(trace, pickup_spec)
    assert 'the operator forced failed on look_down at step 2; the task assumed it never happens ' \
           '(look_down_x is no proposition of the specification)' in [v.message for v in report.violations]


def test_a_goal_the_operator_forced_is_not_counted_and_the_check_says_who(pickup_spec):
    following = [('/manipulate', ['manipulate'], [('manipulate', 'completed')]),
                 ('/pickup_object', ['pickup_object'], [('pickup_object', 'completed')])]
    trace = forced_failure_of_look_down(following, 'finished')
    trace.steps[2].forced, trace.steps[2].forced_propositions = 'done', ['look_down_c']
    report = check_trace(trace, pickup_spec)
    assert [v.message for v in report.violations if v.kind == 'goal_order'] == [
        "the run ended in 'finished' but goal(s) look_down, pickup_object were never completed in order "
        '(the operator forced done on look_down at step 2, not the robot)']
