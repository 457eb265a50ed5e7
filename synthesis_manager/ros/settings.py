"""A node's settings (synthesis_manager.settings) as its ROS parameters."""

from __future__ import annotations

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node

from synthesis_manager.settings import Setting


class NodeSettings:
    """The current values of a node's declared settings, read by name: ``settings.timeout``
    (a parameter set since, e.g. with ``ros2 param set``, is read as it is now)."""

    def __init__(self, node: Node, settings: tuple[Setting, ...]):
        self._node, self._names = node, frozenset(item.name for item in settings)

    def __getattr__(self, name: str):
        if name.startswith('_') or name not in self._names:
            raise AttributeError(f'{self._node.get_name()} declares no setting {name!r}')
        return self._node.get_parameter(name).value


def declare_settings(node: Node, settings: tuple[Setting, ...]) -> NodeSettings:
    """Declare ``settings`` as ``node``'s ROS parameters (their meaning is each one's description)."""
    for item in settings:
        node.declare_parameter(item.name, item.default_value(), ParameterDescriptor(
            description=item.meaning, additional_constraints=item.limits, dynamic_typing=item.dynamic_typing))
    return NodeSettings(node, settings)
