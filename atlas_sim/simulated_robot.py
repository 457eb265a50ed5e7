"""The in-process simulator as the executive's robot (ROS-free): :class:`SimulatedRobot`.

The one place the simulator (``atlas_sim.simulator``) and the executive (``atlas_sim.executive``)
meet, besides the closed-loop run (``atlas_sim.closed_loop``).
"""

from __future__ import annotations

from atlas_sim.executive.robot import CapabilityResult


class SimulatedRobot:
    """The :class:`Robot` protocol on an in-process ``AtlasSimulator`` (fast: no ROS)."""

    def __init__(self, simulator):
        self.simulator = simulator

    def start_concurrently(self, capabilities):
        return self.simulator.start_concurrently(list(capabilities))

    def step(self) -> None:
        self.simulator.step()

    def result(self, handle) -> CapabilityResult | None:
        done = handle.result
        return None if done is None else CapabilityResult(done.name, done.outcome, done.reason, done.finished_at)

    def snapshot(self) -> dict:
        return self.simulator.snapshot()
