"""The action servers' goal policy without ROS (synthesis_manager.goals): how many goals run
and are accepted at once, which refused goals get fixes searched, and what a goal's result says."""

import threading

import pytest

from respec.vocabulary.errors import ErrorCode
from synthesis_manager.goals import GoalAdmission, PipelineOutcome, byproduct_name, wants_fixes
from synthesis_manager.limits import BusyError
from synthesis_manager.requests import SynthesisTask

TASK = SynthesisTask('atlas', ['stand_prep'], ['look_down'], ['finished', 'failed'])


def test_beyond_max_active_goals_running_the_next_is_busy_and_beyond_twice_accepted_rejected():
    limit = [2]
    admission = GoalAdmission(lambda: limit[0])
    assert [admission.accept() for _ in range(5)] == [True, True, True, True, False]
    with admission.running(), admission.running():
        with pytest.raises(BusyError, match=r'2 goals in progress \(max_active_goals 2\)'):
            with admission.running():
                pass
    with admission.running():  # the finished ones no longer count
        pass
    admission.finished()
    assert admission.accept()
    limit[0] = 0  # the setting is read at each goal
    with pytest.raises(BusyError):
        with admission.running():
            pass


def test_admission_counts_stay_right_under_concurrent_goals():
    admission = GoalAdmission(lambda: 1000)

    def goals():
        for _ in range(200):
            assert admission.accept()
            with admission.running():
                pass
            admission.finished()
    threads = [threading.Thread(target=goals) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert [admission.accept() for _ in range(2000)].count(True) == 2000 and not admission.accept()


def test_only_tasks_refused_as_impossible_with_a_budget_get_fixes_searched():
    refused = PipelineOutcome(ErrorCode.SPEC_UNSYNTHESIZABLE, 'no')
    assert wants_fixes(3.0, refused, TASK)
    assert not wants_fixes(0.0, refused, TASK)
    assert not wants_fixes(3.0, PipelineOutcome(ErrorCode.SYNTHESIS_TIMEOUT, 'late'), TASK)
    given = SynthesisTask('atlas', [], [], [], option='ltl_synthesis_only')
    assert not wants_fixes(3.0, refused, given)


def test_a_result_lists_the_suggested_fixes_after_its_message():
    outcome = PipelineOutcome(ErrorCode.SPEC_UNSYNTHESIZABLE, 'impossible')
    assert outcome.message_with_fixes() == 'impossible'
    outcome.suggest(['add a transition', 'drop a goal'])
    assert outcome.fixes == ['Suggested fix 1: add a transition', 'Suggested fix 2: drop a goal']
    assert outcome.message_with_fixes().startswith('impossible\n\nVerified fixes')
    assert outcome.message_with_fixes().endswith('\n  Suggested fix 1: add a transition\n  Suggested fix 2: drop a goal')


def test_byproducts_are_named_by_the_behavior_else_the_system_and_goal():
    assert byproduct_name(TASK, 'abcdef0123456789') == 'atlas_abcdef01'
    assert byproduct_name(SynthesisTask('', [], [], []), 'abcdef0123456789') == 'behavior_abcdef01'
