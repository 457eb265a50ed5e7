"""The ROS runtime foundation: loopback-only DDS settings and the command line."""

import os
import subprocess
import sys

from synthesis_manager.ros_env import prepare_ros_environment


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
