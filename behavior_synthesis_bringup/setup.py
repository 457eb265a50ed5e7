"""The launch package: share/behavior_synthesis_bringup/launch/*.launch.py, the ament index entry
that `ros2 launch behavior_synthesis_bringup ...` finds them by, and the module they use to find
the suite (colcon, or `pip install --prefix`)."""

from setuptools import setup

PACKAGE = 'behavior_synthesis_bringup'

setup(
    name=PACKAGE,
    version='0.1.0',
    packages=[PACKAGE],
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{PACKAGE}']),
        (f'share/{PACKAGE}', ['package.xml']),
        (f'share/{PACKAGE}/launch', ['launch/suite.launch.py', 'launch/atlas_onboard.launch.py']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    description='Launch file of the behavior synthesis suite',
    license='BSD-3-Clause',
)
