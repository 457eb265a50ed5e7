"""The command line: serve, send-goal (JSON, errors, Ctrl-C cancels), demo and goal parsing."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest
from rclpy.node import Node

from respec.vocabulary.naming import parse_names
from synthesis_manager.requests import InvalidRequestError, selected_option
from synthesis_manager.ros.env import prepare_ros_environment
from synthesis_manager.ros.harness import RosHarness
from synthesis_msgs.action import BehaviorSynthesis
from waiting import wait_until

pytestmark = pytest.mark.ros

CLI = [str(Path(sys.executable).parent / 'behavior-synthesis')]


@pytest.mark.parametrize('text, names', [
    ('look_down, pickup_object', ['look_down', 'pickup_object']),
    ('look_down,pickup_object', ['look_down', 'pickup_object']),
    ("['look_down', 'pickup_object']", ['look_down', 'pickup_object']),
    ('look_down pickup_object', ['look_down', 'pickup_object']),
    (['stand_prep'], ['stand_prep']),
    ('', []),
])
def test_goal_strings_are_parsed_like_the_original_and_the_webui(text, names):
    assert parse_names(text) == names


def test_synthesis_options_are_mutually_exclusive():
    options = SimpleNamespace(ltl_compilation_only=False, ltl_synthesis_only=False, ltl_steps_only=True)
    assert selected_option(options) == 'ltl_steps_only'
    options.ltl_compilation_only = True
    with pytest.raises(InvalidRequestError, match='mutually exclusive'):
        selected_option(options)


@pytest.fixture
def served(tmp_path):
    """`behavior-synthesis serve` in its own process on a reserved domain; yields its environment."""
    from synthesis_manager.ros.harness import reserve_domain_id

    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        server = subprocess.Popen(CLI + ['serve', '--byproducts-dir', str(tmp_path)], env=environment,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        assert 'suite up' in server.stdout.readline()
        yield environment
        server.send_signal(signal.SIGINT)
        assert server.wait(20) == 130  # README: stopped by SIGINT


def send_goal(environment, *arguments, timeout=120):
    return subprocess.run(CLI + ['send-goal', *arguments], env=environment, capture_output=True,
                          text=True, timeout=timeout)


def test_send_goal_prints_one_json_object(served):
    result = send_goal(served, '--system', 'atlas', '--initial-conditions', 'stand_prep',
                       '--goals', 'look_down,pickup_object', '--json')
    assert result.returncode == 0, result.stderr
    outcome = json.loads(result.stdout)
    assert outcome['error_code'] == 1 and outcome['error_name'] == 'SUCCESS'
    assert outcome['states'] and all(len(state) == 16 for state in outcome['states'])


def test_send_goal_shows_progress_and_a_readable_summary(served):
    result = send_goal(served, '--initial-conditions', 'manipulate', '--goals', 'footstep_execution')
    assert result.returncode == 0, result.stderr
    assert '100%' in result.stderr
    assert 'result: SUCCESS' in result.stdout and 'footstep_execution' in result.stdout


def test_send_goal_fails_with_the_code_and_message(served):
    result = send_goal(served, '--goals', 'look_down,levitate', '--json')
    assert result.returncode == 1
    outcome = json.loads(result.stdout)
    assert outcome['error_name'] == 'UNKNOWN_PROPOSITION' and 'levitate' in outcome['message']
    assert 'did you mean' not in outcome['message']  # nothing close to "levitate"
    misspelled = send_goal(served, '--goals', 'look_dwon')
    assert misspelled.returncode == 1
    assert "unknown goal 'look_dwon': not an action or control mode of atlas; did you mean look_down?" \
        in misspelled.stdout


def test_send_goal_gives_the_sentence_naming_the_missing_transition(served):
    result = send_goal(served, '--initial-conditions', 'stand', '--goals', 'look_down,stand_prep')
    assert result.returncode == 1 and 'result: INVALID_GOALS' in result.stdout
    # the goals in order: the pre-check's sentence (as for a start in stand_prep), then the diagnosis
    assert ('Goal 2 (stand_prep) can never be achieved: goal 1 (look_down) needs the robot in stand, and stand -> '
            'stand_prep is not a transition in config/atlas.yaml (from stand the robot can only change to '
            'manipulate, step, walk).') in result.stdout
    assert 'Unrealizable core' in result.stdout and 'How the environment wins' in result.stdout


def test_ctrl_c_cancels_the_goal(served, tmp_path):
    # A synthesis that never ends by itself: 2**80 initial states for the strategy.
    runaway = tmp_path / 'runaway.json'
    runaway.write_text(json.dumps({'env_props': [f'x{i}' for i in range(40)],
                                   'sys_props': [f'y{i}' for i in range(40)], 'sys_liveness': ['y0']}))
    with RosHarness(domain_id=int(served['ROS_DOMAIN_ID'])) as ros:  # the goal's feedback, as a client sees it
        statuses = []
        ros.add_node(Node, 'feedback_watcher').create_subscription(
            BehaviorSynthesis.Impl.FeedbackMessage, '/behavior_synthesis/_action/feedback',
            lambda message: statuses.append(message.feedback.status), 10)
        process = subprocess.Popen(CLI + ['send-goal', '--synthesis-only', str(runaway), '--json'],
                                   env=served, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        wait_until(lambda: any(status.startswith('Synthesizing') for status in statuses), 60,
                   'the runaway goal synthesizing (its feedback)')
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert json.loads(stdout)['error_name'] == 'PREEMPTED'


# Not 2x faster (issue 50): it asserts send-goal's default 10 s wait for a server and its message (10.4 s, 10 s of
# them the wait).
def test_send_goal_without_a_server_says_what_it_waits_for_at_once_and_that_it_uses_the_demo_task():
    from synthesis_manager.ros.harness import reserve_domain_id

    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        started = time.monotonic()
        process = subprocess.Popen(CLI + ['send-goal'], env=environment, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True)
        first_lines = [process.stderr.readline(), process.stderr.readline()]
        said_within = time.monotonic() - started
        rest = process.stderr.read()
        assert process.wait(60) == 5  # ExitStatus.UNAVAILABLE
    assert first_lines == ['send-goal: no --goals given: using the demo task --initial-conditions stand_prep '
                           '--goals look_down,pickup_object\n', 'send-goal: waiting for /behavior_synthesis…\n']
    assert said_within < 5.0  # at once (the interpreter and rclpy start), not after the 10 s wait
    assert 'no /behavior_synthesis action server after 10 s (start one with `behavior-synthesis serve`' in rest


@pytest.mark.parametrize('command, defaults', [
    ('send-goal', ['(default: atlas)', "(default: the system's own", '(default: finished,failed)',
                   '(default: 120.0)', "(default: the paper's demo task, look_down,pickup_object"]),
    ('execute', ['(default: atlas)', '(default: 10.0)', '(default: 300.0)',
                 '--verbose', 'Exit status:']),
    ('gui', ['(default 127.0.0.1: this machine only)', '(default: 600.0)']),
])
def test_help_shows_the_defaults(command, defaults):
    result = subprocess.run(CLI + [command, '--help'], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0
    text = ' '.join(result.stdout.split())  # argparse wraps lines
    for default in defaults:
        assert default in text, (default, result.stdout)


def test_demo_writes_every_artifact(tmp_path):
    result = subprocess.run(CLI + ['demo', '--output-dir', str(tmp_path)], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert 'realizable: yes' in result.stdout and 'specification: 12 inputs' in result.stdout
    for name in ('demo.structuredslugs', 'demo.slugsin', 'demo.json', 'state_machine.yaml',
                 'state_machine.json', 'state_machine.dot', 'state_machine.svg', 'state_machine.png'):
        assert (tmp_path / name).stat().st_size > 0, name
    assert json.loads((tmp_path / 'demo.json').read_text())['nodes']


@pytest.mark.parametrize('action', ['behavior_synthesis', 'flexbe_synthesis'])
def test_send_goal_shows_the_error_name_and_message_of_either_interface(served, action):
    result = send_goal(served, '--action', action, '--system', 'system_wide', '--goals', 'look_down,levitate')
    assert result.returncode == 1
    assert 'UNKNOWN_PROPOSITION' in result.stderr.splitlines()[-1]  # the last feedback, in the progress line
    summary = result.stdout.splitlines()
    assert any('UNKNOWN_PROPOSITION' in line for line in summary[:2]), result.stdout
    assert any(line.startswith('message: ') and 'levitate' in line for line in summary), result.stdout
    success = send_goal(served, '--action', action, '--system', 'system_wide', '--json')
    assert json.loads(success.stdout)['error_name'] == 'SUCCESS', success.stdout


@pytest.mark.parametrize('script', ['ltl-compilation-node', 'ltl-synthesis-node', 'sm-generation-node',
                                    'behavior-synthesis-server', 'atlas-sim-node'])
def test_node_scripts_answer_help_instead_of_starting(script):
    result = subprocess.run([str(Path(sys.executable).parent / script), '--help'], capture_output=True, text=True,
                            timeout=30)
    assert result.returncode == 0 and result.stdout.startswith(f'usage: {script} [--ros-args')
    assert 'ready' not in result.stdout  # it did not start the node
