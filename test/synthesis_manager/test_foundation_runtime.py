"""The ROS runtime foundation: loopback-only DDS settings and the command line."""

import os
import socket
import subprocess
import sys

import pytest

from synthesis_manager.ros.env import prepare_ros_environment

pytestmark = pytest.mark.ros


def test_prepare_sets_loopback_and_drops_conflicting_settings():
    environ = {'ROS_LOCALHOST_ONLY': '1', 'ROS_STATIC_PEERS': '10.0.0.7',
               'ROS_DISCOVERY_SERVER': '10.0.0.8:11811',
               'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET'}
    prepare_ros_environment(domain_id=42, environ=environ)
    assert environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert environ['ROS_DOMAIN_ID'] == '42'
    for name in ('ROS_LOCALHOST_ONLY', 'ROS_STATIC_PEERS', 'ROS_DISCOVERY_SERVER'):
        assert name not in environ
    assert os.path.isfile(environ['FASTRTPS_DEFAULT_PROFILES_FILE'])


def test_test_process_itself_is_on_loopback():
    assert os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'


def test_command_line_help_lists_subcommands():
    result = subprocess.run([sys.executable, '-m', 'synthesis_manager', '--help'],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    for command in ('demo', 'serve', 'send-goal', 'compile', 'execute', 'gui'):
        assert command in result.stdout


PACKAGES = ('respec', 'ltl_specification', 'ltl_synthesizer', 'sm_generation', 'synthesis_manager',
            'atlas_sim')
ROS_INIT_OWNERS = {'synthesis_manager/ros/env.py', 'synthesis_manager/ros/harness.py'}


def test_rclpy_is_initialised_only_by_the_loopback_helpers():
    """Every entry point reaches rclpy.init() through ros.env.init_ros or RosHarness."""
    import re
    from pathlib import Path

    call = re.compile(r'^\s*(\w+\s*=\s*)?rclpy\.init\(', re.MULTILINE)
    root = Path(__file__).resolve().parents[2]
    offenders = [str(path.relative_to(root)) for package in PACKAGES
                 for path in (root / package).rglob('*.py')
                 if call.search(path.read_text())
                 and str(path.relative_to(root)) not in ROS_INIT_OWNERS]
    assert ROS_INIT_OWNERS <= {str(p.relative_to(root)) for p in (root / 'synthesis_manager').rglob('*.py')
                               if call.search(p.read_text())}
    assert offenders == []


def capture_environment_at_init(monkeypatch):
    import rclpy

    seen = {}

    def fake_init(*args, **kwargs):
        seen.update(os.environ)
        raise RuntimeError('stop here')

    monkeypatch.setattr(rclpy, 'init', fake_init)
    return seen


def test_init_ros_applies_loopback_before_rclpy_init(monkeypatch):
    import pytest

    from synthesis_manager.ros.env import init_ros

    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'SUBNET')
    monkeypatch.setenv('ROS_STATIC_PEERS', '192.0.2.1')
    seen = capture_environment_at_init(monkeypatch)
    with pytest.raises(RuntimeError, match='stop here'):
        init_ros()
    assert seen['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert 'ROS_STATIC_PEERS' not in seen


def test_harness_applies_loopback_before_rclpy_init(monkeypatch):
    import pytest

    from synthesis_manager.ros.harness import RosHarness

    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'SUBNET')
    seen = capture_environment_at_init(monkeypatch)
    with pytest.raises(RuntimeError, match='stop here'):
        with RosHarness():
            pass
    assert seen['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'


def test_a_ros_test_runs_on_a_domain_reserved_for_it(ros_domain_of_test):
    """The processes a test starts with os.environ (``execute --engine flexbe`` and its onboard
    engine) are on a domain no other test may reserve while it runs, under pytest-xdist too."""
    from domain_coordinator.impl import PORT_BASE

    from synthesis_manager.ros.harness import environment_domain_id

    assert environment_domain_id() == ros_domain_of_test
    with socket.socket() as other_reservation, pytest.raises(OSError):
        other_reservation.bind(('', PORT_BASE + ros_domain_of_test))


def test_a_finished_harness_leaves_no_domain_behind(monkeypatch):
    """After the harness its domain is free for others: processes started later must not join it."""
    from synthesis_manager.ros.harness import RosHarness

    monkeypatch.setenv('ROS_DOMAIN_ID', '0')
    with RosHarness() as ros:
        assert os.environ['ROS_DOMAIN_ID'] == str(ros.domain_id) != '0'
    assert os.environ['ROS_DOMAIN_ID'] == '0'
    monkeypatch.delenv('ROS_DOMAIN_ID')
    with RosHarness():
        pass
    assert 'ROS_DOMAIN_ID' not in os.environ
