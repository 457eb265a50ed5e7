"""Shared fixtures. ROS tests use ``ros``: an in-process harness on a reserved domain."""

import os

import pytest

from synthesis_manager.ros.env import prepare_ros_environment

# Every test process keeps DDS on loopback, whether or not it starts ROS itself.
prepare_ros_environment()
os.environ.setdefault('MUJOCO_GL', 'egl')


@pytest.fixture
def ros():
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness() as harness:
        yield harness
