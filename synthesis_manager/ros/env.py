"""Prepare the ROS 2 environment before ``rclpy.init()``: DDS stays on loopback.

Every entry point and the test harness call :func:`prepare_ros_environment` first. Fast DDS
reads these variables when a context is initialised, so setting them later has no effect.
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` keeps discovery and data on 127.0.0.1 (an XML
profile alone does not: multicast discovery would still leave the host).
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


def prepare_ros_environment(domain_id: int | None = None, environ=os.environ) -> dict:
    """Set the loopback-only DDS settings (and optionally ROS_DOMAIN_ID) in ``environ``.

    Returns ``environ`` so the same call prepares a subprocess environment too.
    """
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
