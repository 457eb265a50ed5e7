"""DDS beyond this host only when the deployer says so (docs/deployment.md)."""

import pytest

from synthesis_manager.ros.env import prepare_ros_environment

pytestmark = pytest.mark.ros


def test_the_network_scope_keeps_the_deployers_discovery_settings():
    environ = {'BEHAVIOR_SYNTHESIS_DDS_SCOPE': 'network', 'ROS_STATIC_PEERS': '192.0.2.7;192.0.2.8',
               'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SYSTEM_DEFAULT', 'ROS_LOCALHOST_ONLY': '1'}
    prepare_ros_environment(domain_id=7, environ=environ)
    assert environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SYSTEM_DEFAULT'
    assert environ['ROS_STATIC_PEERS'] == '192.0.2.7;192.0.2.8'
    assert 'ROS_LOCALHOST_ONLY' not in environ and environ['ROS_DOMAIN_ID'] == '7'
    assert environ['RMW_IMPLEMENTATION'] == 'rmw_fastrtps_cpp'


def test_the_network_scope_discovers_on_the_subnet_when_nothing_else_is_said():
    environ = prepare_ros_environment(environ={'BEHAVIOR_SYNTHESIS_DDS_SCOPE': 'network'})
    assert environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SUBNET'


def test_any_other_scope_stays_on_loopback():
    environ = prepare_ros_environment(environ={'BEHAVIOR_SYNTHESIS_DDS_SCOPE': 'lan',
                                               'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET',
                                               'ROS_STATIC_PEERS': '192.0.2.7'})
    assert environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST' and 'ROS_STATIC_PEERS' not in environ
