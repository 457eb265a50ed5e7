"""The robot the executive drives (ROS-free): the :class:`Robot` protocol and what a capability returns.

``atlas_sim.simulated_robot.SimulatedRobot`` is this protocol on the in-process simulator,
``synthesis_manager.ros.atlas_sim_robot.RosRobot`` the same protocol over ROS 2.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, Sequence


@dataclass(frozen=True)
class CapabilityResult:
    """How one activation of a capability ended, on the robot's clock."""

    capability: str
    outcome: str  # 'completed' or 'failed'
    reason: str
    time: float


class Robot(Protocol):
    """What the executive needs from a robot (or its simulator)."""

    def start_concurrently(self, capabilities: Sequence[str]) -> list[Any]:
        """Start capabilities in one instant; returns one opaque handle per capability."""

    def step(self) -> None:
        """Let the robot run for a short while (one control period)."""

    def result(self, handle) -> CapabilityResult | None:
        """The result of a started capability, or None while it runs."""

    def snapshot(self) -> dict:
        """Robot state: at least time, mode, completed_actions, sensors, pelvis_height, fallen."""
