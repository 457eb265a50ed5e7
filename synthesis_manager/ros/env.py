"""Prepare the ROS 2 environment before ``rclpy.init()``: DDS stays on loopback.

Every entry point and the test harness call :func:`prepare_ros_environment` first. Fast DDS
reads these variables when a context is initialised, so setting them later has no effect.
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` keeps discovery and data on 127.0.0.1 (an XML
profile alone does not: multicast discovery would still leave the host).

Across hosts is a deliberate choice of whoever deploys: ``BEHAVIOR_SYNTHESIS_DDS_SCOPE=network``
keeps the environment's ``ROS_AUTOMATIC_DISCOVERY_RANGE`` (SUBNET when unset) and
``ROS_STATIC_PEERS`` (docs/deployment.md).
"""

from __future__ import annotations

import os
from pathlib import Path

LOOPBACK_SETTINGS = {
    'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
    'RMW_IMPLEMENTATION': 'rmw_fastrtps_cpp',
}
# Settings that would widen or redirect discovery beyond this host.
CONFLICTING_SETTINGS = ('ROS_LOCALHOST_ONLY', 'ROS_STATIC_PEERS', 'ROS_DISCOVERY_SERVER')
FAST_DISCOVERY_PROFILE = Path(__file__).with_name('fastdds_loopback.xml')
# The deployer's opt-in to DDS beyond this host, and its one value.
DDS_SCOPE_VARIABLE, NETWORK_SCOPE = 'BEHAVIOR_SYNTHESIS_DDS_SCOPE', 'network'


def prepare_ros_environment(domain_id: int | None = None, environ=os.environ) -> dict:
    """Set the loopback-only DDS settings (and optionally ROS_DOMAIN_ID) in ``environ``.

    Returns ``environ`` so the same call prepares a subprocess environment too. With
    ``BEHAVIOR_SYNTHESIS_DDS_SCOPE=network`` the discovery settings are the deployer's.
    """
    if environ.get(DDS_SCOPE_VARIABLE) == NETWORK_SCOPE:
        environ['RMW_IMPLEMENTATION'] = LOOPBACK_SETTINGS['RMW_IMPLEMENTATION']
        environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'SUBNET')
        environ.pop('ROS_LOCALHOST_ONLY', None)  # deprecated; ROS_AUTOMATIC_DISCOVERY_RANGE says it
    else:
        environ.update(LOOPBACK_SETTINGS)
        for name in CONFLICTING_SETTINGS:
            environ.pop(name, None)
    environ.setdefault('FASTRTPS_DEFAULT_PROFILES_FILE', str(FAST_DISCOVERY_PROFILE))
    if domain_id is not None:
        environ['ROS_DOMAIN_ID'] = str(domain_id)
    return environ


def init_ros(args: list[str] | None = None, domain_id: int | None = None, context=None):
    """``rclpy.init()`` after :func:`prepare_ros_environment`; returns the context used."""
    prepare_ros_environment(domain_id)
    import rclpy  # imported here so the environment is in place before rclpy loads the rmw

    if context is None:
        context = rclpy.get_default_context()
    rclpy.init(args=args, context=context, domain_id=domain_id)
    return context
