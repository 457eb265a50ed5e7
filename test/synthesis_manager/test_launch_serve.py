"""The launch arguments of suite.launch.py -> serve's command line (ROS-free; the real
`ros2 launch` runs in test/integration/test_ros2_launch.py)."""

import json

import pytest

from synthesis_manager.programs.launch_serve import ROS_ARGS, launch_values, main, serve_argv, serve_launch_arguments
from synthesis_manager.programs.cli import build_parser

pytestmark = pytest.mark.ros


def test_values_become_serves_options_and_empty_ones_keep_its_defaults():
    values = launch_values(['config_dir:=/a:/b', 'byproducts_dir:=', 'namespace:=/robot1, /robot2',
                            'synthesis_timeout:=60', f"{ROS_ARGS}:=-r __ns:='/x y'"])
    argv = serve_argv(values)
    assert argv == ['--config-dir', '/a:/b', '--synthesis-timeout', '60', '--namespace', '/robot1',
                    '--namespace', '/robot2', '--ros-args', '-r', '__ns:=/x y']
    parsed = build_parser(only='serve').parse_args(['serve', *argv[:argv.index('--ros-args')]])
    assert (parsed.config_dir, parsed.synthesis_timeout, parsed.namespaces) == ('/a:/b', 60.0, ['/robot1', '/robot2'])
    assert serve_argv({}) == []


def test_an_unknown_launch_argument_is_refused_naming_it():
    with pytest.raises(ValueError, match="'colour:=red' is no launch argument"):
        launch_values(['colour:=red'])
    assert main(['colour:=red']) == 2


def test_arguments_as_json_name_every_option_once(capsys):
    assert main(['--arguments']) == 0
    names = [argument['name'] for argument in json.loads(capsys.readouterr().out)]
    assert len(names) == len(set(names)) and names[-1] == ROS_ARGS
    assert names[:-1] == [argument.name for argument in serve_launch_arguments()]
