"""The robot the executive drives (ROS-free): the :class:`Robot` protocol, the in-process
:class:`SimulatedRobot` and the simulator factory.

``synthesis_manager.nodes.atlas_sim_robot.RosRobot`` is the same protocol over ROS 2.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, Sequence

from atlas_sim.config import system_config
from respec.errors import CodedError, ErrorCode
from respec.naming import COMPLETED


class InitialConditionError(CodedError, ValueError):
    """An initial condition the simulator cannot start in; ``item`` names it."""

    code = ErrorCode.INVALID_INITIAL_CONDITIONS


class FaultSpecError(CodedError, ValueError):
    """A malformed fault ('capability:k') or one naming an unknown capability; ``item`` names it."""

    code = ErrorCode.INVALID_REQUEST


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


def parse_faults(fail=(), fail_first=(), probability=()) -> dict:
    """Fault entries (``simulation.faults`` shape) from command-line style lists.

    ``fail``: capability names that always fail; ``fail_first``: 'capability:k' (the first
    k attempts fail); ``probability``: 'capability:p'. Raises FaultSpecError naming the entry.
    """
    faults: dict[str, dict] = {}
    for name in fail:
        faults.setdefault(name, {})['always'] = True
    for entry, key, convert in [(e, 'fail_first', int) for e in fail_first] + \
                               [(e, 'probability', float) for e in probability]:
        name, _, value = entry.partition(':')
        try:
            faults.setdefault(name.strip(), {})[key] = convert(value)
        except ValueError:
            raise FaultSpecError(f'expected CAPABILITY:{"K" if convert is int else "P"}, got {entry!r}',
                                 item=entry) from None
    return faults


def make_simulator(system: str = 'atlas', config_dir: str | Path | None = None, initial_conditions=(),
                   faults: dict | None = None, seed: int | None = None, **simulation_changes):
    """An ``AtlasSimulator`` for ``system``, started in the given initial conditions.

    ``initial_conditions`` name at most one control mode (the initial mode; default: the
    config's) and actions that have already completed. ``faults`` (capability -> entry of
    ``simulation.faults``) are added to the config's, ``seed`` replaces its seed.
    """
    from atlas_sim.simulator import AtlasSimulator  # here: importing the executor needs no MuJoCo

    config = system_config(system, config_dir)
    modes = [c for c in initial_conditions if c in config.abstraction.control_modes]
    actions = [c for c in initial_conditions if c in config.abstraction.actions]
    unknown = [c for c in initial_conditions if c not in modes and c not in actions]
    if unknown:
        raise InitialConditionError(f'initial condition {unknown[0]!r} is neither a control mode nor an '
                                    f'action of {system}', item=unknown[0])
    if len(modes) > 1:
        raise InitialConditionError(f'initial conditions name several control modes: {modes[0]!r} and '
                                    f'{modes[1]!r}', item=modes[1])
    capabilities = {*config.abstraction.control_modes, *config.abstraction.actions}
    for name in faults or {}:
        if name not in capabilities:
            raise FaultSpecError(f'fault for {name!r}, which is not a capability of {system}', item=name)
    changes = dict(simulation_changes)
    if modes:
        changes['initial_mode'] = modes[0]
    if faults:
        changes['faults'] = {**config.simulation.faults, **faults}
    if seed is not None:
        changes['seed'] = int(seed)
    config = dataclasses.replace(config, simulation=dataclasses.replace(config.simulation, **changes))
    simulator = AtlasSimulator(config)
    for action in actions:  # completed before the run: as if they had just reported completion
        simulator.semantics.finish(simulator.state, action, COMPLETED)
    return simulator
