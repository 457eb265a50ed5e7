"""The simulated ATLAS, its operator and FlexBE's onboard engine: what a behavior synthesized
for `atlas` runs on.

    ros2 launch behavior_synthesis_bringup atlas_onboard.launch.py [robot:=false] [operator:=false]

The robot (`atlas-sim-node`) and the headless operator (`atlas-sim-operator`, answering
InputState as flexbe_input does) are the suite's scripts, found beside its `behavior-synthesis`;
the onboard engine is FlexBE's `flexbe_onboard.start_behavior` in the Python that runs `ros2`
(your ROS installation's, which has FlexBE). Start behaviors with
`behavior-synthesis start-behavior NAME` or FlexBE's be_launcher.
"""

import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration

from behavior_synthesis_bringup import suite_script


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='true', description='start the simulated ATLAS (atlas-sim-node)'),
        DeclareLaunchArgument('operator', default_value='true',
                              description="start the headless operator answering InputState (atlas-sim-operator); "
                                          "false when you run flexbe_input's input server"),
        DeclareLaunchArgument('onboard', default_value='true', description="start FlexBE's onboard engine"),
        ExecuteProcess(cmd=[suite_script('atlas-sim-node')], name='atlas_sim', output='screen',
                       condition=IfCondition(LaunchConfiguration('robot'))),
        ExecuteProcess(cmd=[suite_script('atlas-sim-operator')], name='operator', output='screen',
                       condition=IfCondition(LaunchConfiguration('operator'))),
        ExecuteProcess(cmd=[sys.executable, '-m', 'flexbe_onboard.start_behavior'], name='flexbe_onboard',
                       output='screen', condition=IfCondition(LaunchConfiguration('onboard'))),
    ])
