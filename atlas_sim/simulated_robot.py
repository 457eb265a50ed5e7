"""The in-process simulator as the executive's robot (ROS-free): :class:`SimulatedRobot`.

The one place the simulator (``atlas_sim.simulator``) and the executive (``atlas_sim.executive``)
meet, besides the closed-loop run (``atlas_sim.closed_loop``).
"""

from __future__ import annotations

import dataclasses

from atlas_sim.executive.robot import CapabilityResult
from atlas_sim.simulator.operator_data import datum_refusal, operator_answer


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

    # the operator's inputs (the executive's RuntimeControl asks the user) -----------------------

    def input_default(self, capability: str):
        """What the simulator's own operator would answer for the input action ``capability``."""
        kind = self.simulator.provides.get(capability)
        return None if kind is None else operator_answer(self.simulator.settings, capability, kind)

    def give_input(self, capability: str, value) -> None:
        """The user's answer for ``capability``'s next request: None (the user aborted) or a
        value that is no valid datum makes the input fail, as FlexBE's InputState would
        (aborted / data_error); a valid one is what the actions that need it receive."""
        kind = self.simulator.provides.get(capability)
        valid = value is not None and (kind is None or datum_refusal(kind, value, self.simulator.settings.scene) is None)
        self.simulator.set_operator_input(capability, valid)
        if valid and kind is not None:
            settings = self.simulator.settings
            answers = {**settings.scenario.operator_answers, capability: value}
            self.simulator.settings = dataclasses.replace(
                settings, scenario=dataclasses.replace(settings.scenario, operator_answers=answers))
