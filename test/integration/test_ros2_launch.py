"""``ros2 launch behavior_synthesis_bringup suite.launch.py``, run by the real ``ros2 launch`` (the pinned
launch 3.4.3 and launch_ros/ros2launch 0.26.6 that `make flexbe` installs beside ros2cli, with our
launch package installed into that prefix as colcon installs an ament_python package), with the
suite's ``behavior-synthesis`` at the end of PATH as a user's shell has it.

Its launch arguments are read from ``serve``'s parser: a ``serve`` option without a launch
argument fails here. The suite it starts answers ``ros2 action send_goal`` with a state machine
on a private ROS_DOMAIN_ID, and Ctrl-C (SIGINT to the terminal's process group) stops every
process of it within 3 s, with status 0 and no "process has died".
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from synthesis_manager.programs.launch_serve import serve_parser

ROS2 = Path(sys.prefix) / 'ros2cli' / 'ros2'
LAUNCH = ['launch', 'behavior_synthesis_bringup', 'suite.launch.py']
GOAL = ("{request: {name: launched, system: atlas, goal: 'look_down, pickup_object', "
        "initial_condition: stand_prep, sm_outcomes: [finished, failed]}}")

pytestmark = [pytest.mark.usefixtures('flexbe'), pytest.mark.ros, pytest.mark.flexbe]


@pytest.fixture(scope='module')
def ros2() -> Path:
    assert ROS2.exists(), f'no {ROS2}: run `make flexbe` (it installs the pinned ros2cli and ros2 launch)'
    return ROS2


def serve_options() -> set[str]:
    """``serve``'s long options (but --help), as launch argument names."""
    return {option[2:].replace('-', '_') for action in serve_parser()._actions for option in action.option_strings
            if option.startswith('--') and option != '--help'}


def with_suite_on_path(environment) -> dict:
    """A user's shell: their ros2, and the suite's bin folder at the end of PATH."""
    return dict(environment, PATH=f'{environment.get("PATH", "")}{os.pathsep}{Path(sys.executable).parent}')


def test_every_serve_option_is_a_launch_argument(ros2):
    shown = subprocess.run([str(ros2), *LAUNCH, '--show-args'], capture_output=True, text=True, timeout=60,
                           env=with_suite_on_path(dict(os.environ)))
    assert shown.returncode == 0, shown.stderr
    arguments = set(re.findall(r"^\s+'(\w+)':", shown.stdout, flags=re.M))
    assert serve_options() >= {'config_dir', 'namespace', 'strategy_cache_dir', 'synthesis_timeout', 'nodes'}
    assert serve_options() - arguments == set(), shown.stdout
    assert arguments - serve_options() == {'ros_args'}, shown.stdout


def group_processes(group: int) -> list[str]:
    import psutil

    found = []
    for process in psutil.process_iter(['pid', 'cmdline']):
        try:
            if os.getpgid(process.info['pid']) == group:
                found.append(' '.join(process.info['cmdline'] or []))
        except (ProcessLookupError, psutil.NoSuchProcess):
            pass
    return found


def test_ros2_launch_serves_a_goal_and_stops_on_ctrl_c(ros2, ros, tmp_path):
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient
    from synthesis_manager.ros.env import prepare_ros_environment

    environment = with_suite_on_path(prepare_ros_environment(
        ros.domain_id, environ=dict(os.environ, ROS_LOG_DIR=str(tmp_path / 'ros_log'))))
    log = open(tmp_path / 'launch.log', 'w+', encoding='utf-8')  # noqa: SIM115 - closed below
    launch = subprocess.Popen([str(ros2), *LAUNCH, f'byproducts_dir:={tmp_path / "byproducts"}',
                               'synthesis_timeout:=90', f'strategy_cache_dir:={tmp_path / "cache"}'],
                              env=environment, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    group = launch.pid
    try:
        client = SynthesisClient(ros.add_node(Node, 'launch_test_client'), 'behavior_synthesis')
        assert client.wait_for_server(timeout=90.0), (tmp_path / 'launch.log').read_text()[-3000:]
        sent = subprocess.run([str(ros2), 'action', 'send_goal', '/behavior_synthesis',
                               'synthesis_msgs/action/BehaviorSynthesis', GOAL],
                              env=environment, capture_output=True, text=True, timeout=180)
        assert 'Goal finished with status: SUCCEEDED' in sent.stdout, (sent.stdout[-2000:], sent.stderr[-2000:])
        result = sent.stdout[sent.stdout.index('Result:'):]
        assert re.search(r'error_code:\s+value: 1\b', result) and result.count('state_path:') >= 5, result[:800]

        stopped = time.monotonic()
        os.killpg(group, signal.SIGINT)   # Ctrl-C in the terminal: the whole foreground group
        status = launch.wait(timeout=20)
        seconds = time.monotonic() - stopped
        left = group_processes(group)
    finally:
        if launch.poll() is None:
            os.killpg(group, signal.SIGKILL)
            launch.wait()
        log.close()
    output = (tmp_path / 'launch.log').read_text()
    assert status == 0 and left == [], (status, left, output[-3000:])
    assert seconds < 3.0, (seconds, output[-3000:])
    assert 'process has died' not in output and 'behavior synthesis suite up' in output, output[-3000:]
