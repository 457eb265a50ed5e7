"""The /behavior_synthesis action server end to end, all nodes in-process (launch-free)."""

import os
import threading
import time
from argparse import Namespace
from dataclasses import replace
from pathlib import Path

import pytest

import endless_diagnosis as endless_diagnosis_module
from suite_settings import suite_args
from waiting import wait_until
from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_manager.suite import suite_node_factories

pytestmark = pytest.mark.ros

PAPER_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'pickup_object'])


@pytest.fixture
def suite(ros, tmp_path):
    from rclpy.node import Node

    nodes = [ros.add_node(factory) for factory in suite_node_factories(suite_args(tmp_path))]
    client = SynthesisClient(ros.add_node(Node, 'test_client'))
    assert client.wait_for_server(timeout=10.0)
    return Namespace(client=client, nodes=nodes, byproducts=tmp_path, ros=ros)


def run(suite, **goal):
    return suite.client.run(make_goal(**goal), timeout=120)


def test_paper_task_end_to_end(suite):
    from sm_generation import StateInstantiation, validate_state_machine

    feedback = []
    outcome = suite.client.run(make_goal(**PAPER_TASK), feedback=lambda s, p: feedback.append((s, p)))
    assert outcome.error_name == 'SUCCESS', outcome.message
    assert validate_state_machine([StateInstantiation.from_dict(s) for s in outcome.states]) == []
    classes = {s['state_class'] for s in outcome.states}
    assert {'TiltHeadState', ':BEHAVIOR', 'ChangeControlModeActionState'} <= classes
    root = next(s for s in outcome.states if s['state_path'] == '/')
    assert sorted(root['outcomes']) == ['failed', 'finished']
    progress = [p for _, p in feedback]
    assert progress == sorted(progress) and progress[-1] == pytest.approx(1.0)
    assert {'look_down_a', 'pickup_object_a', 'stand_a', 'manipulate_a'} <= set(
        outcome.ltl_specification['sys_props'])
    assert outcome.automaton['states']
    for suffix in ('.structuredslugs', '.slugsin', '.json'):
        assert list(suite.byproducts.glob(f'*{suffix}')), suffix


def test_second_paper_task_and_a_walk_task(suite):
    footsteps = run(suite, system='atlas', initial_conditions=['manipulate'], goals=['footstep_execution'])
    assert footsteps.error_name == 'SUCCESS', footsteps.message
    assert any('ExecuteStepPlanActionState' == s['state_class'] for s in footsteps.states)
    walk = run(suite, system='atlas', initial_conditions=['stand_prep'], goals=['walk'])
    assert walk.error_name == 'SUCCESS', walk.message
    assert any('"walk"' in s['parameter_values'] for s in walk.states)


def test_compile_only_and_ltl_steps_only(suite):
    compiled = run(suite, option='ltl_compilation_only', **PAPER_TASK)
    assert compiled.error_name == 'SUCCESS'
    assert compiled.ltl_specification['sys_trans'] and not compiled.automaton['states']
    assert compiled.states == []
    automaton_only = run(suite, option='ltl_steps_only', **PAPER_TASK)
    assert automaton_only.error_name == 'SUCCESS'
    assert automaton_only.automaton['states'] and automaton_only.states == []


def test_synthesis_only_uses_the_given_specification(suite):
    compiled = run(suite, option='ltl_compilation_only', **PAPER_TASK)
    synthesized = run(suite, system='atlas', initial_conditions=[], goals=[],
                      option='ltl_synthesis_only', ltl_specification=compiled.ltl_specification)
    assert synthesized.error_name == 'SUCCESS', synthesized.message
    assert synthesized.automaton['states']
    assert 'look_down_a' in synthesized.automaton['output_variables']


def test_custom_ltl_is_merged(suite):
    custom = {'sys_trans': ['!grasp_object_a']}
    outcome = run(suite, option='ltl_compilation_only', ltl_specification=custom, **PAPER_TASK)
    assert outcome.error_name == 'SUCCESS', outcome.message
    assert any('grasp_object_a' in f for f in outcome.ltl_specification['sys_trans'])


def test_bad_requests_get_specific_codes_and_the_server_keeps_serving(suite):
    unknown_goal = run(suite, system='atlas', initial_conditions=['stand_prep'], goals=['fly_away'])
    assert unknown_goal.error_name == 'UNKNOWN_PROPOSITION'
    assert 'fly_away' in unknown_goal.message
    unknown_system = run(suite, system='r2d2', initial_conditions=['stand_prep'], goals=['look_down'])
    assert unknown_system.error_name == 'UNKNOWN_SYSTEM' and 'r2d2' in unknown_system.message
    no_goals = run(suite, system='atlas', initial_conditions=['stand_prep'], goals=[])
    assert no_goals.error_name == 'INVALID_GOALS'
    malformed = run(suite, system='atlas', initial_conditions=[], goals=[], option='ltl_synthesis_only',
                    ltl_specification={'sys_props': ['x'], 'sys_trans': ['x &']})
    assert malformed.error_name == 'INVALID_FORMULA'
    assert 'sys_trans[0]' in malformed.message
    unrealizable = run(suite, system='atlas', initial_conditions=[], goals=[], option='ltl_synthesis_only',
                       ltl_specification={'env_props': ['door_open'], 'sys_props': ['inside'],
                                          'env_trans': ['!next(door_open)'],
                                          'sys_trans': ['next(inside) -> next(door_open)'],
                                          'sys_liveness': ['inside']})
    assert unrealizable.error_name == 'SPEC_UNSYNTHESIZABLE'
    assert 'inside' in unrealizable.message
    odd_name = run(suite, name='../escape', **PAPER_TASK)  # mapped to a file name inside the directory
    assert odd_name.error_name == 'SUCCESS' and (suite.byproducts / 'x--2e-2e.escape.slugsin').exists()
    assert not (suite.byproducts.parent / 'escape.slugsin').exists()
    goal = make_goal(**PAPER_TASK)
    goal.synthesis_options.ltl_compilation_only = True
    goal.synthesis_options.ltl_steps_only = True
    assert suite.client.run(goal).error_name == 'INVALID_REQUEST'
    assert run(suite, **PAPER_TASK).error_name == 'SUCCESS'


def test_four_goals_in_flight_at_once(suite):
    tasks = [PAPER_TASK,
             dict(system='atlas', initial_conditions=['manipulate'], goals=['footstep_execution']),
             dict(system='atlas', initial_conditions=['stand_prep'], goals=['walk']),
             dict(system='atlas', initial_conditions=['stand_prep'], goals=['pickup_object'])]
    outcomes = [None] * len(tasks)

    def send(index):
        outcomes[index] = run(suite, **tasks[index])

    threads = [threading.Thread(target=send, args=(i,)) for i in range(len(tasks))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(120)
    assert [o.error_name for o in outcomes] == ['SUCCESS'] * 4


def test_same_request_gives_identical_results(suite):
    first, second = run(suite, **PAPER_TASK), run(suite, **PAPER_TASK)
    assert first.ltl_specification == second.ltl_specification
    assert first.automaton == second.automaton
    assert first.states == second.states


def test_impossible_goal_order_is_explained_in_plain_words_first(suite):
    feedback = []
    outcome = suite.client.run(make_goal(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'stand_prep']),
                               feedback=lambda s, p: feedback.append(s), timeout=120)
    assert outcome.error_name == 'SPEC_UNSYNTHESIZABLE'
    first_line = outcome.message.splitlines()[0]
    assert first_line.startswith('Goal 2 (stand_prep) can never be achieved')
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in first_line
    assert 'eq. (9) control-mode topology for stand' in outcome.message
    assert 'Details from the synthesizer:' in outcome.message  # the synthesizer's own account stays


# --- the diagnosis of unrealizable tasks: a cancel and the time limit end it at once ---------

IMPOSSIBLE_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'stand_prep'])


@pytest.fixture
def endless_diagnosis(suite, monkeypatch, tmp_path):
    """The suite's synthesis node diagnoses with test/endless_diagnosis.py; yields its pid file."""
    from ltl_synthesizer.isolated import SynthesisProcesses
    from respec.child_processes.runner import SERVER_CHILD_NICENESS

    test_dir = str(Path(__file__).resolve().parents[1])
    monkeypatch.setenv('PYTHONPATH', os.pathsep.join(filter(None, [test_dir, os.environ.get('PYTHONPATH')])))
    pid_file = tmp_path / 'diagnosis.pid'
    monkeypatch.setenv('ENDLESS_DIAGNOSIS_PID_FILE', str(pid_file))
    service = synthesis_node_of(suite).service
    monkeypatch.setattr(service, 'explainers', replace(service.explainers,
                                                       diagnose=endless_diagnosis_module.endless_diagnosis))
    # Children that import the stand-in: started from now on, with the test folder on their path.
    processes = SynthesisProcesses(niceness=SERVER_CHILD_NICENESS)
    monkeypatch.setattr(service, 'processes', processes)
    yield pid_file
    processes.close()


def server_of(suite):
    from synthesis_manager.nodes.server_node import BehaviorSynthesisServer

    return next(node for node in suite.nodes if isinstance(node, BehaviorSynthesisServer))


def synthesis_node_of(suite):
    from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode

    return next(node for node in suite.nodes if isinstance(node, LTLSynthesisNode))


def process_gone(pid: int, within: float) -> bool:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        try:
            with open(f'/proc/{pid}/stat') as stat:
                if stat.read().rsplit(')', 1)[1].split()[0] == 'Z':  # ended, not yet reaped
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.02)
    return False


def test_a_cancel_ends_the_diagnosis_at_once(suite, endless_diagnosis):
    cancel, cancelled_at = threading.Event(), []

    def on_feedback(status, _):
        if status.startswith('Synthesizing') and not cancel.is_set():
            deadline = time.monotonic() + 20  # the diagnosis process is busy once it wrote its pid
            while not endless_diagnosis.exists() and time.monotonic() < deadline:
                time.sleep(0.05)
            cancelled_at.append(time.monotonic())
            cancel.set()

    outcome = suite.client.run(make_goal(**IMPOSSIBLE_TASK), feedback=on_feedback, cancel=cancel, timeout=60)
    assert outcome.error_name == 'PREEMPTED', outcome.message
    assert time.monotonic() - cancelled_at[0] < 1.0
    assert process_gone(int(endless_diagnosis.read_text()), within=1.0)
    assert run(suite, **PAPER_TASK).error_name == 'SUCCESS'  # the server keeps serving


def test_the_diagnosis_time_limit_keeps_the_synthesizers_verdict(suite, endless_diagnosis):
    from rclpy.parameter import Parameter
    from ltl_synthesizer.service import DIAGNOSIS_GRACE

    server_of(suite).set_parameters([Parameter('diagnosis_timeout', value=1.0)])
    diagnosing = []  # when the diagnosis process began (it writes its pid): its time limit counts
    # from just before; timed from the goal's start, a loaded machine's synthesis counted too
    watcher = threading.Thread(target=lambda: diagnosing.append(
        wait_until(endless_diagnosis.exists, 60, 'the diagnosis process started') and time.monotonic()))
    watcher.start()
    outcome = suite.client.run(make_goal(**IMPOSSIBLE_TASK), timeout=60)
    answered = time.monotonic()
    watcher.join()
    assert outcome.error_name == 'SPEC_UNSYNTHESIZABLE'
    assert 'Details from the synthesizer' not in outcome.message  # no diagnosis: the synthesizer's account
    assert outcome.message.strip()
    # Stopped at its 1 s (not the default 20 s): killed DIAGNOSIS_GRACE later, and the answer's
    # way back through the nodes took up to 3.2 s more at load 7 (5.2 s): 10 s in all, half the default.
    assert answered - diagnosing[0] < 1.0 + DIAGNOSIS_GRACE + 8.0
    assert process_gone(int(endless_diagnosis.read_text()), within=1.0)
