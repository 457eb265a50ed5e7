"""The suite's robot systems on ROS: the compilation node serves them, a GUI elsewhere reads them.

The topic ``robot_systems`` (std_msgs/String, latched) carries ``respec.robot.catalog_to_json``
of the compilation node's config directory: what rebuilds every system (its files' parsed
content written out again, not the files' text: ``respec.robot.system.served_files``). A GUI attached to a
running suite (``gui --connect``) builds its RobotSystems from them, so it shows and checks the
systems the suite synthesizes for, never config files of its own machine.
"""

from __future__ import annotations

import threading

from std_msgs.msg import String

from respec.robot import RobotSystem, ServedCatalog
from synthesis_manager.ros.qos import latched_qos

ROBOT_SYSTEMS_TOPIC = 'robot_systems'


def create_systems_publisher(node):
    return node.create_publisher(String, ROBOT_SYSTEMS_TOPIC, latched_qos())


class SuiteSystems:
    """The systems a running suite serves (``names``/``load`` as SystemCatalog), kept current."""

    def __init__(self, node, wait: float = 5.0):
        self._received = threading.Event()
        self._lock = threading.Lock()
        self._catalog = ServedCatalog({})
        self._wait = wait
        node.create_subscription(String, ROBOT_SYSTEMS_TOPIC, self._on_systems, latched_qos())

    def _on_systems(self, message: String) -> None:
        catalog = ServedCatalog.from_json(message.data)
        with self._lock:
            self._catalog = catalog
        self._received.set()

    def _current(self) -> ServedCatalog:
        self._received.wait(self._wait)  # the first message arrives once discovery has matched
        with self._lock:
            return self._catalog

    def names(self) -> list[str]:
        return self._current().names()

    def load(self, name: RobotSystem | str) -> RobotSystem:
        return self._current().load(name)
