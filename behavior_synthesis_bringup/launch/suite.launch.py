"""The behavior synthesis suite, as `behavior-synthesis serve` starts it.

    ros2 launch behavior_synthesis_bringup suite.launch.py config_dir:=DIR namespace:=/robot1,/robot2

Every `serve` option is a launch argument (`--show-args` lists them): the suite's Python (the
interpreter of the `behavior-synthesis` on PATH, or named by $BEHAVIOR_SYNTHESIS) reads them
from serve's own parser and runs serve with their values.
"""

import json
import subprocess

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration

from behavior_synthesis_bringup import suite_python


def generate_launch_description():
    python = suite_python()
    described = subprocess.run([python, '-m', 'synthesis_manager.programs.launch_serve', '--arguments'],
                               capture_output=True, text=True, check=True, timeout=60)
    arguments = json.loads(described.stdout)
    return LaunchDescription([
        *[DeclareLaunchArgument(a['name'], default_value='', description=a['description']) for a in arguments],
        ExecuteProcess(cmd=[python, '-m', 'synthesis_manager.programs.launch_serve',
                            *[[f"{a['name']}:=", LaunchConfiguration(a['name'])] for a in arguments]],
                       name='behavior_synthesis', output='screen', emulate_tty=True),
    ])
