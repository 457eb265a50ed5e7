"""Reliability of the ROS suite: bursts, BUSY, fairness, lost goals, killed nodes, bad input, byproducts.

Shutdown within 3 s of SIGINT/SIGTERM, entry point by entry point: test_entry_point_shutdown.py.

Figures for bigger runs (50 goals to ``serve``, 20 GUI jobs, a 2,000-goal soak with its RSS
slope) are printed by bench/bench_reliability.py.
"""

import contextlib
import math
import os
import signal
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from lost_responses import GoalResponseLosingClient
from runaway_requests import runaway_goal
from suite_in_process import PAPER_TASK, start_suite
from waiting import wait_until
from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_manager.limits import MAX_LIST_LENGTH, MAX_STRING_BYTES
from synthesis_manager.requests import byproduct_file_stem
from synthesis_manager.ros.env import prepare_ros_environment
from synthesis_manager.ros.harness import RosHarness, reserve_domain_id
from synthesis_msgs.srv import SynthesizeAutomaton

pytestmark = pytest.mark.ros

def run_all(client, goals, timeout=120.0):
    """Send every goal at once (one thread each); returns outcomes (or exceptions) in order."""
    outcomes = [None] * len(goals)

    def run(index):
        try:
            outcomes[index] = client.run(goals[index], timeout=timeout)
        except Exception as error:  # noqa: BLE001 - a hang shows up as TimeoutError here
            outcomes[index] = error

    threads = [threading.Thread(target=run, args=(index,)) for index in range(len(goals))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return outcomes


@contextlib.contextmanager
def slow_goals_running(client, count):
    """``count`` runaway syntheses in progress (cancelled on leaving); yields their threads."""
    cancel, synthesizing = threading.Event(), set()

    def feedback(index):
        return lambda status, _progress: status.startswith('Synthesizing') and synthesizing.add(index)
    threads = [threading.Thread(target=client.run, args=(runaway_goal(30.0),),
                                kwargs={'cancel': cancel, 'feedback': feedback(index)}) for index in range(count)]
    for thread in threads:
        thread.start()
    try:
        wait_until(lambda: len(synthesizing) == count, 60, f'{count} runaway goals synthesizing (their feedback)')
        yield threads
    finally:
        cancel.set()
        for thread in threads:
            thread.join(timeout=60)


def names(outcomes):
    return Counter(getattr(outcome, 'error_name', repr(outcome)) for outcome in outcomes)


# --- load ---------------------------------------------------------------------------------

def test_fifty_goals_at_once_all_get_their_result(ros, tmp_path):
    client = start_suite(ros, tmp_path)
    goals = [make_goal(**PAPER_TASK, name=f'burst{i}',
                       option='ltl_compilation_only' if i % 5 == 0 else None) for i in range(50)]
    outcomes = run_all(client, goals)
    assert names(outcomes) == {'SUCCESS': 50}
    assert all(outcome.states for i, outcome in enumerate(outcomes) if i % 5)


def test_goals_beyond_the_limit_are_answered_busy_at_once(ros, tmp_path):
    client = start_suite(ros, tmp_path, server_parameters=[Parameter('max_active_goals', value=2)])
    with slow_goals_running(client, 2):
        started = time.monotonic()
        outcome = client.run(make_goal(**PAPER_TASK), timeout=30)
        assert outcome.error_name == 'BUSY', outcome.message
        assert 'max_active_goals 2' in outcome.message
        assert time.monotonic() - started < 5


def test_fast_goals_are_not_starved_by_slow_ones(ros, tmp_path):
    client = start_suite(ros, tmp_path)
    with slow_goals_running(client, 4) as slow:
        started = time.monotonic()
        outcomes = run_all(client, [make_goal(**PAPER_TASK, name=f'fast{i}') for i in range(10)], timeout=60)
        assert names(outcomes) == {'SUCCESS': 10}
        assert all(thread.is_alive() for thread in slow)  # the slow ones are still at it
        assert time.monotonic() - started < 45


# Not 2x faster (issue 50): 300 goals, ten in flight, are the soak; fewer would be a shorter soak (5.4 s).
def test_a_short_soak_loses_no_goal(ros, tmp_path):
    """300 goals back to back, ten in flight (the 2,000-goal soak is in bench/)."""
    client = start_suite(ros, tmp_path, synthesis_parameters=[Parameter('keep_byproducts', value=20)])
    goals = [make_goal(**PAPER_TASK, name=f'soak{i}',
                       option='ltl_compilation_only' if i % 2 else 'ltl_steps_only') for i in range(300)]
    outcomes = []
    for start in range(0, len(goals), 10):
        outcomes += run_all(client, goals[start:start + 10], timeout=60)
    assert names(outcomes) == {'SUCCESS': 300}
    assert len({path.name.split('.')[0] for path in tmp_path.glob('*.json')}) == 20


def test_a_goal_whose_response_is_lost_goes_on_from_the_servers_status(ros, tmp_path, monkeypatch, capfd):
    start_suite(ros, tmp_path)
    monkeypatch.setattr('synthesis_manager.client.RaceFreeActionClient', GoalResponseLosingClient)
    client = SynthesisClient(ros.add_node(Node, 'losing_client'))
    assert client.wait_for_server(timeout=10.0)
    started = time.monotonic()
    outcome = client.run(make_goal(**PAPER_TASK), timeout=30)
    assert client.action_client.lost == 1 and outcome.error_name == 'SUCCESS', outcome.message
    assert outcome.states  # the whole result: the state machine
    assert time.monotonic() - started < 25  # the grace, not the 30 s time limit
    assert 'its status lists the goal as accepted, so it goes on' in capfd.readouterr().err


# --- bad input ----------------------------------------------------------------------------

@pytest.mark.parametrize('timeout', [-1.0, math.nan, math.inf])
def test_bad_goal_time_limits_are_invalid_requests(ros, tmp_path, timeout):
    client = start_suite(ros, tmp_path)
    outcome = client.run(make_goal(**PAPER_TASK, timeout=timeout), timeout=30)
    assert outcome.error_name == 'INVALID_REQUEST'
    assert 'timeout must be a finite number' in outcome.message


def test_oversized_strings_are_refused_without_echo(ros, tmp_path):
    client = start_suite(ros, tmp_path)
    huge = 'x' * (2 * MAX_STRING_BYTES)
    for goal in (make_goal(**PAPER_TASK, name=huge),
                 make_goal(system='atlas', initial_conditions=['stand_prep'], goals=[huge]),
                 make_goal(**PAPER_TASK, ltl_specification={'sys_trans': [huge]})):
        outcome = client.run(goal, timeout=30)
        assert outcome.error_name == 'INVALID_REQUEST', outcome.message
        assert f'{2 * MAX_STRING_BYTES} bytes' in outcome.message
        assert len(outcome.message) < 400
    assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'


def test_long_lists_and_control_characters_are_refused_naming_the_field(ros, tmp_path):
    """Issue 34 items 6 and 11: a list over MAX_LIST_LENGTH, a NUL that used to cut the goal
    short (SUCCESS with half the task; serialization cuts it, so our client refuses it unsent),
    a line break in a name: each INVALID_REQUEST at once."""
    client = start_suite(ros, tmp_path)
    for goal, named in [
            (make_goal(**PAPER_TASK, sm_outcomes=['finished'] * (MAX_LIST_LENGTH + 1)), 'goal.request.sm_outcomes'),
            (make_goal(system='atlas', initial_conditions=['stand_prep'], goals=['look_down\x00', 'pickup_object']),
             'goal.request.goal'),
            (make_goal(**PAPER_TASK, name='two\nlines'), 'goal.request.name')]:
        started = time.monotonic()
        outcome = client.run(goal, timeout=30)
        assert outcome.error_name == 'INVALID_REQUEST', outcome.message
        assert named in outcome.message and len(outcome.message) < 400
        assert time.monotonic() - started < 2.0
    assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'


def test_the_synthesis_service_refuses_bad_time_limits(ros, tmp_path):
    start_suite(ros, tmp_path, names=('ltl_synthesis',))
    node = ros.add_node(Node, 'direct_client')
    service = node.create_client(SynthesizeAutomaton, 'ltl_synthesis')
    assert service.wait_for_service(timeout_sec=10)
    from synthesis_manager.ros.harness import wait_for

    response = wait_for(service.call_async(SynthesizeAutomaton.Request(timeout=-5.0, spec_name='x')), 30)
    assert response.error_code.value == response.error_code.INVALID_REQUEST
    assert 'request.timeout' in response.error_code.message


# --- byproducts ---------------------------------------------------------------------------

def test_dotted_spec_names_do_not_overwrite_each_other(ros, tmp_path):
    client = start_suite(ros, tmp_path)
    for name in ('collide.one', 'collide.two'):
        assert client.run(make_goal(**PAPER_TASK, name=name, option='ltl_steps_only'),
                          timeout=60).error_name == 'SUCCESS'
    stems = [byproduct_file_stem(name) for name in ('collide.one', 'collide.two')]
    assert sorted(path.name for path in tmp_path.iterdir() if not path.name.startswith('.')) == [
        f'{stem}.{extension}' for stem in stems for extension in ('json', 'slugsin', 'structuredslugs')]


def test_keeping_no_byproducts_leaves_the_directory_empty(ros, tmp_path):
    client = start_suite(ros, tmp_path / 'byproducts',
                         synthesis_parameters=[Parameter('keep_byproducts', value=0)])
    assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'
    assert not (tmp_path / 'byproducts').exists() or not list((tmp_path / 'byproducts').iterdir())


# --- faults -------------------------------------------------------------------------------

# Not 2x faster (issue 50): ltl_synthesis is a serve process of its own, killed 1 s into a synthesis, then the suite
# recovers for a next goal (6.4 s).
def test_a_killed_node_is_reported_by_name_and_the_suite_recovers(tmp_path):
    """ltl_synthesis runs in its own process and is killed (SIGKILL) mid-synthesis."""
    serve = [str(Path(sys.executable).parent / 'behavior-synthesis'), 'serve', '--nodes', 'ltl_synthesis',
             '--byproducts-dir', str(tmp_path)]
    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        process = subprocess.Popen(serve, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            with RosHarness(domain_id=domain) as ros:
                client = start_suite(ros, tmp_path, names=('ltl_compilation', 'sm_generation'))
                probe = ros.nodes[-1].create_client(SynthesizeAutomaton, 'ltl_synthesis')
                assert probe.wait_for_service(timeout_sec=60)
                killed = []

                def kill_while_synthesizing(status, _progress):
                    if status.startswith('Synthesizing') and not killed:
                        threading.Timer(1.0, lambda: (process.kill(), killed.append(time.monotonic()))).start()

                outcome = client.run(runaway_goal(), feedback=kill_while_synthesizing, timeout=60)
                noticed_after = time.monotonic() - killed[0]
                assert outcome.error_name == 'SERVICE_UNAVAILABLE', outcome.message
                assert "node '/ltl_synthesis'" in outcome.message
                assert noticed_after < 2.0
                process.wait(timeout=10)

                process = subprocess.Popen(serve, env=environment, stdout=subprocess.DEVNULL,
                                           stderr=subprocess.DEVNULL)
                assert probe.wait_for_service(timeout_sec=60)
                assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'
        finally:
            process.send_signal(signal.SIGTERM)
            process.wait(timeout=20)



# --- memory ---------------------------------------------------------------------------------

def test_a_synthesis_over_its_memory_limit_ends_with_a_clear_error(ros, tmp_path):
    # 32 MB, not 64: the same failure, sooner (measured back to back beside other jobs: 16 MB
    # reached in 0.5 s, 32 in 11 s, 64 in 43 s); the paper task afterwards needs less than 16.
    client = start_suite(ros, tmp_path, synthesis_parameters=[Parameter('memory_limit_mb', value=32)])
    started = time.monotonic()
    outcome = client.run(runaway_goal(120.0), timeout=180)
    assert outcome.error_name == 'SYNTHESIS_FAILED', outcome.message
    assert '32' in outcome.message and 'memory' in outcome.message
    assert time.monotonic() - started < 120
    assert client.run(make_goal(**PAPER_TASK), timeout=60).error_name == 'SUCCESS'


# --- hostile input (issue 25) -----------------------------------------------------------------

def test_deeply_nested_custom_ltl_gets_its_specific_code_at_once(ros, tmp_path):
    """5,000 parentheses (within the limit) are read like any formula; beyond the one nesting
    limit of every parser the answer is INVALID_FORMULA with a short message, no traceback."""
    from respec.nesting import MAX_FORMULA_NESTING
    limit = sys.getrecursionlimit()  # raised only where formulas are read, never process-wide
    client = start_suite(ros, tmp_path)
    within = client.run(make_goal(**PAPER_TASK, option='ltl_compilation_only', ltl_specification={
        'sys_trans': ['(' * 5000 + 'look_down_a' + ')' * 5000]}), timeout=60)
    assert within.error_name == 'SUCCESS', within.message
    depth = MAX_FORMULA_NESTING + 1
    for formula in ('(' * depth + 'look_down_a' + ')' * depth, '!' * 3 * depth + 'look_down_a'):
        started = time.monotonic()
        outcome = client.run(make_goal(**PAPER_TASK, ltl_specification={'sys_trans': [formula]}), timeout=60)
        assert time.monotonic() - started < 5
        assert outcome.error_name == 'INVALID_FORMULA', outcome.message[:300]
        assert f'nested deeper than {MAX_FORMULA_NESTING}' in outcome.message and len(outcome.message) < 300
        # The same code from the ltl_synthesis service, which parses a whole specification.
        direct = client.run(make_goal('atlas', [], [], option='ltl_synthesis_only', ltl_specification={
            'sys_props': ['look_down_a'], 'sys_trans': [formula]}), timeout=60)
        assert direct.error_name == 'INVALID_FORMULA', direct.message[:300]
        assert f'nested deeper than {MAX_FORMULA_NESTING}' in direct.message and len(direct.message) < 300
    assert sys.getrecursionlimit() == limit


def test_a_yaml_bomb_in_synthesis_options_is_refused_at_once(ros, tmp_path):
    from synthesis_manager.client import make_flexbe_goal
    start_suite(ros, tmp_path)
    client = SynthesisClient(ros.add_node(Node, 'flexbe_client'), 'flexbe_synthesis')
    assert client.wait_for_server(timeout=10.0)
    goal = make_flexbe_goal(**PAPER_TASK)
    goal.synthesis_options = '\n'.join(['a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]'] + [
        f'a{i}: &a{i} [' + ', '.join([f'*a{i - 1}'] * 9) + ']' for i in range(1, 9)])
    started = time.monotonic()
    outcome = client.run(goal, timeout=60)
    assert time.monotonic() - started < 5
    assert 'INVALID_REQUEST' in outcome.message and 'aliases' in outcome.message
    assert len(outcome.message) < 300


def test_goal_time_limits_hold_under_load(ros, tmp_path):
    """Behind syntheses that fill every worker, a goal's limit counts its queue wait: each is
    answered within a second of its limit (counted from sending); an invalid limit is refused
    at once."""
    client = start_suite(ros, tmp_path, synthesis_parameters=[Parameter('parallel_syntheses', value=2)])
    # The load comes from another client: this client's own share (max_client_goals) is not what is tested.
    with slow_goals_running(SynthesisClient(ros.add_node(Node, 'load_client')), 2):
        started = time.monotonic()
        invalid = client.run(make_goal(**PAPER_TASK, timeout=-1.0), timeout=30)
        assert invalid.error_name == 'INVALID_REQUEST' and time.monotonic() - started < 1.0
        limited = run_all(client, [make_goal(**PAPER_TASK, name=f'limited{i}', timeout=2.0) for i in range(6)])
        assert names(limited) == Counter({'SYNTHESIS_TIMEOUT': 6}), [o.message for o in limited]
        assert all("time limit of 2 s passed" in outcome.message for outcome in limited)
        assert max(outcome.seconds for outcome in limited) < 2.0 + 1.0


def test_a_burst_with_short_limits_is_answered_within_a_second_of_them(ros, tmp_path):
    """Issue 34 item 10: 100 goals sent at once, half whole pipelines and half
    runaway syntheses, each with a 1 s limit: every one is answered (its result, its time limit
    or BUSY) within a second of its limit, counted from sending (bench_reliability: in processes
    of their own). rclpy took one goal per executor pass: accepted over seconds, answered seconds late."""
    client = start_suite(ros, tmp_path)
    goals = [make_goal(**PAPER_TASK, name=f'short{i}', timeout=1.0) if i % 2 else runaway_goal(1.0)
             for i in range(100)]
    outcomes = run_all(client, goals)
    assert set(names(outcomes)) <= {'SUCCESS', 'TIMEOUT', 'SYNTHESIS_TIMEOUT', 'BUSY'}, names(outcomes)
    assert max(outcome.seconds for outcome in outcomes) < 1.0 + 1.0, sorted(o.seconds for o in outcomes)[-5:]


def test_a_goal_asking_for_forever_gets_the_servers_cap(ros, tmp_path):
    """Issue 34 item 5: a goal asking for 1e9 s runs under max_goal_timeout, and its feedback and
    result name the cap."""
    # A cap of 4 s: the paper task under it took over 2 s at load 7 on the 2 cores.
    client = start_suite(ros, tmp_path, server_parameters=[Parameter('max_goal_timeout', value=4.0)])
    statuses = []
    started = time.monotonic()
    outcome = client.run(runaway_goal(1e9), feedback=lambda status, _progress: statuses.append(status), timeout=60)
    assert outcome.error_name == 'SYNTHESIS_TIMEOUT', outcome.message
    assert 'time limit of 4 s passed' in outcome.message and 'max_goal_timeout' in outcome.message
    assert 'asked for 1e+09 s' in statuses[0]
    assert time.monotonic() - started < 4.0 + 1.0
    capped = client.run(make_goal(**PAPER_TASK, timeout=1e9), timeout=60)
    assert capped.error_name == 'SUCCESS', capped.message


def test_a_flood_is_rejected_on_arrival_and_reported_busy(ros, tmp_path):
    client = start_suite(ros, tmp_path, server_parameters=[Parameter('max_active_goals', value=0)])
    started = time.monotonic()
    outcome = client.run(make_goal(**PAPER_TASK), timeout=30)
    assert outcome.error_name == 'BUSY' and 'rejected' in outcome.message
    assert time.monotonic() - started < 2


def default_qos_client(ros):
    """A client as the ros2 CLI and the FlexBE WebUI make it: rclpy's default depth-10 queues."""
    from rclpy.action import ActionClient
    from synthesis_msgs.action import BehaviorSynthesis

    client = ActionClient(ros.add_node(Node, 'default_qos_client'), BehaviorSynthesis, 'behavior_synthesis')
    assert client.wait_for_server(timeout_sec=10)
    return client


def test_a_default_qos_client_hears_every_answer_of_a_bounded_burst(ros, tmp_path):
    """10 goals sent at once by a plain rclpy client (results asked for as each goal is
    accepted, as the ros2 CLI does): every goal is answered. 10 is what its queues hold
    (docs/limits.md: such a client sends at most 10 goals before their answers arrive); the
    server takes a burst MAX_TAKEN goals at a time, fewer than that."""
    from synthesis_manager.ros.action_server import MAX_TAKEN
    from synthesis_manager.ros.conversions import error_name
    assert MAX_TAKEN <= 10
    start_suite(ros, tmp_path)
    client = default_qos_client(ros)
    sent = [client.send_goal_async(make_goal(**PAPER_TASK, name=f'plain{i}', option='ltl_compilation_only'))
            for i in range(10)]
    results = []
    deadline = time.monotonic() + 60
    for future in sent:
        while not future.done():
            assert time.monotonic() < deadline, 'a goal response was lost'
            time.sleep(0.01)
        assert future.result().accepted
        results.append(future.result().get_result_async())
    for future in results:
        while not future.done():
            assert time.monotonic() < deadline, 'a result was lost'
            time.sleep(0.01)
    assert Counter(error_name(f.result().result.error_code.value) for f in results) == {'SUCCESS': 10}


def test_a_result_asked_for_after_its_retention_is_a_timeout_not_a_success(ros, tmp_path):
    """rclpy answers a result request for a goal its server forgot with status UNKNOWN and an
    empty result (error code 0): our client reports TIMEOUT saying why."""
    from synthesis_manager.client import outcome_from_response
    from synthesis_manager.ros.harness import wait_for
    start_suite(ros, tmp_path, server_parameters=[Parameter('result_retention', value=1.0)])
    client = default_qos_client(ros)
    handle = wait_for(client.send_goal_async(make_goal(**PAPER_TASK, option='ltl_compilation_only')), 30)
    assert outcome_from_response(wait_for(handle.get_result_async(), 30), 0.0).error_name == 'SUCCESS'

    def forgotten():  # 1 s after the goal finished
        late = outcome_from_response(wait_for(handle.get_result_async(), 30), 0.0)
        return late if late.goal_status == 'UNKNOWN' else None
    late = wait_until(forgotten, 3.0, 'the result forgotten (result_retention 1 s)')
    assert (late.error_name, late.goal_status) == ('TIMEOUT', 'UNKNOWN')
    assert 'result_retention' in late.message


def test_one_clients_runaways_leave_another_clients_goal_its_usual_latency(ros, tmp_path):
    """Issue 48, item 1: eight goals of one client asking 1e9 s (capped) held all eight
    synthesis workers, and another user's 30 s goal ended SYNTHESIS_TIMEOUT. A client's running
    goals now hold at most max_client_goal_seconds (1200) of time limits together: four of the
    eight run, the others wait, told their place."""
    # No strategy cache: the other client's goal must be synthesized, by a free worker.
    attacker = start_suite(ros, tmp_path, synthesis_parameters=[Parameter('strategy_cache_mb', value=0.0)])
    victim = SynthesisClient(ros.add_node(Node, 'another_client'))
    usual = sorted(victim.run(make_goal(**PAPER_TASK, name=f'usual{i}')).seconds for i in range(3))[1]
    cancel, waiting, statuses = threading.Event(), threading.Event(), []

    def on_feedback(status, _progress):
        statuses.append(status)
        if status.startswith('Waiting:'):
            waiting.set()
    runaways = [threading.Thread(target=attacker.run, args=(runaway_goal(1e9),),
                                 kwargs={'cancel': cancel, 'feedback': on_feedback}) for _ in range(8)]
    for thread in runaways:
        thread.start()
    try:
        assert waiting.wait(30), statuses
        # Long work yields the CPU: the four running ones drop to the lowest priority.
        deadline = time.monotonic() + 30
        while len(children_at_lowest_priority()) < 4:
            assert time.monotonic() < deadline, 'the runaways were never demoted to the lowest CPU priority'
            time.sleep(0.1)
        outcome = victim.run(make_goal(**PAPER_TASK, name='during', timeout=30.0))
        assert outcome.succeeded, outcome.message
        assert any('this goal is number 4 of its waiting goals' in status for status in statuses), statuses
    finally:
        cancel.set()
        for thread in runaways:
            thread.join(timeout=60)
    # The usual latency once more, now: other jobs on the machine come and go (at load 7 one
    # took the paper task from 1.9 to 10 s), and the runaways' share is the question.
    after = victim.run(make_goal(**PAPER_TASK, name='after')).seconds
    print(f'another client: {usual:.2f} s before, {outcome.seconds:.2f} s beside 8 runaways of one client, '
          f'{after:.2f} s after')
    # bench_reliability measures it against the 1 s target on a quiet machine; this margin
    # also holds beside other jobs on 2 cores (before: SYNTHESIS_TIMEOUT after 30 s).
    assert outcome.seconds < max(usual, after) + 2.0


def children_at_lowest_priority() -> list[int]:
    """This process's child processes running at nice 19."""
    from respec.child_processes.runner import LOWEST_PRIORITY

    found = []
    for entry in Path('/proc').iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError):
                fields = (entry / 'stat').read_text().rsplit(')', 1)[1].split()
                if int(fields[1]) == os.getpid() and int(fields[16]) == LOWEST_PRIORITY:
                    found.append(int(entry.name))
    return found
