"""An :class:`AtlasSimulator` for a robot system, started in given initial conditions and with
given faults (``make_simulator``, ``parse_faults``), and the errors naming a bad one.
"""

from __future__ import annotations

import dataclasses

from atlas_sim.simulator.config import SystemConfig
from respec.vocabulary.errors import CodedError, ErrorCode
from respec.vocabulary.naming import COMPLETED
from respec.robot import RobotSystem


class InitialConditionError(CodedError, ValueError):
    """An initial condition the simulator cannot start in; ``item`` names it."""

    code = ErrorCode.INVALID_INITIAL_CONDITIONS


class FaultSpecError(CodedError, ValueError):
    """A malformed fault ('capability:k') or one naming an unknown capability; ``item`` names it."""

    code = ErrorCode.INVALID_REQUEST


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


def make_simulator(system: RobotSystem, initial_conditions=(), faults: dict | None = None,
                   seed: int | None = None, **simulation_changes):
    """An ``AtlasSimulator`` for ``system``, started in the given initial conditions.

    ``initial_conditions`` name at most one control mode (the initial mode; default: the
    config's) and actions that have already completed. ``faults`` (capability -> entry of
    ``simulation.faults``) are added to the config's, ``seed`` replaces its seed.
    """
    from atlas_sim.simulator.atlas_simulator import AtlasSimulator  # here: parse_faults needs no MuJoCo

    config = SystemConfig.of(system)
    modes = [c for c in initial_conditions if c in config.abstraction.control_modes]
    actions = [c for c in initial_conditions if c in config.abstraction.actions]
    unknown = [c for c in initial_conditions if c not in modes and c not in actions]
    if unknown:
        raise InitialConditionError(f'initial condition {unknown[0]!r} is neither a control mode nor an '
                                    f'action of {config.system}', item=unknown[0])
    if len(modes) > 1:
        raise InitialConditionError(f'initial conditions name several control modes: {modes[0]!r} and '
                                    f'{modes[1]!r}', item=modes[1])
    capabilities = {*config.abstraction.control_modes, *config.abstraction.actions}
    for name in faults or {}:
        if name not in capabilities:
            raise FaultSpecError(f'fault for {name!r}, which is not a capability of {config.system}', item=name)
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
