"""A robot system as atlas_sim sees it (``SystemConfig.of(RobotSystem)``).

Two sections of the system file (``config/<system>.yaml``) matter here:

``abstraction``  the discrete model shared with the specification compiler, read and
                 validated by ``respec.robot.abstraction`` (``RobotAbstraction``).
``simulation``   how atlas_sim emulates the system (all keys optional)::

    simulation:
      initial_mode: stand_prep      # default: abstraction.initial_mode, else first mode
      timestep: 0.002               # physics step (s)
      control_period: 0.01          # sim time advanced by one Simulator.step() (s)
      real_time_factor: 0.0         # 0 = as fast as possible, 1 = wall-clock pace
      seed: 0                       # seed of probabilistic faults
      fault_delay: 0.1              # sim time before an injected fault is reported (s)
      settle: {timeout: 3.0, position_tolerance: 0.15, velocity_tolerance: 0.2}
      fall: {min_pelvis_height: 0.45, max_torso_tilt_deg: 40.0}
      modes:                        # control mode -> motion (see atlas_sim.simulator.motions)
        stand: {motion: posture, posture: stand, duration: 1.5}
        walk:  {motion: gait, steps: 4, step_length: 0.15}
      actions:                      # action -> motion
        look_down: {motion: head_tilt, tilt_deg: 45}
        object_template: {motion: operator_input, provides: template_id}
      invalidations:                # on completion of key, forget these completions
        footstep_execution: [footstep_plan]
      scenario:
        operator_inputs: {object_template: true, target_pose: true}
        operator_answers: {object_template: 1}   # what the operator answers (default: by kind)
        sensors: {obj_detected: true}
      scene:                        # objects by template id, reach (see atlas_sim.simulator.operator_data)
        objects: {1: pickup_object}
        reach: 1.0
        look_ahead: true            # walks look for furniture in their way first (SceneConfig)
        clearance: 0.02             # how close (m) a walk may come to furniture
      faults:                       # capability -> fault (see atlas_sim.simulator.faults)
        pickup_object: {fail_first: 1}
      stand_in: "..."               # set when the humanoid does not model this robot but only
                                    # stands in for it (says how); the GUI then offers no simulation

Capabilities without a motion entry get a default: control modes take the
``stand`` posture, actions are short computations (they always complete
unless a precondition or an injected fault says otherwise).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, Mapping, Optional, Tuple

from respec.robot import RobotSystem, robot_system_from_file
from respec.robot.abstraction import RobotAbstraction, abstraction_from_document
from respec.vocabulary.errors import CodedError, ErrorCode

class SimulationConfigError(CodedError, ValueError):
    """The ``simulation:`` section is invalid; ``item`` names the offending key or capability."""

    code = ErrorCode.CONFIG_FILE_INVALID


#: config/ next to the atlas_sim package (the repository layout: atlas_sim/simulator/config.py).
CONFIG_DIR = Path(__file__).resolve().parents[2] / "config"
DEFAULT_CONFIG = CONFIG_DIR / "atlas.yaml"


@dataclass(frozen=True)
class SettleConfig:
    """When a motion counts as settled and how long it may take."""

    timeout: float = 3.0
    position_tolerance: float = 0.15
    velocity_tolerance: float = 0.2


@dataclass(frozen=True)
class ScenarioConfig:
    """What the (simulated) operator and environment provide."""

    operator_inputs: Dict[str, bool] = field(default_factory=dict)
    #: input action -> the answer the operator gives (e.g. a template id)
    operator_answers: Dict[str, Any] = field(default_factory=dict)
    sensors: Dict[str, bool] = field(default_factory=dict)


@dataclass(frozen=True)
class SceneConfig:
    """The objects the robot can act on, by template id (see atlas_sim.simulator.operator_data), and its reach (m).

    ``look_ahead``: a walk first looks for furniture in its way and fails at once, naming it,
    when it would come within ``clearance`` metres of it (false: the robot walks blind and
    runs into it; the contact is reported and the trace check counts it as a violation).
    """

    objects: Dict[int, str] = field(default_factory=lambda: {1: "pickup_object"})
    reach: float = 1.0
    look_ahead: bool = True
    clearance: float = 0.02

    @classmethod
    def from_dict(cls, section: Optional[Mapping[str, Any]]) -> "SceneConfig":
        section = dict(section or {})
        unknown = set(section) - {"objects", "reach", "look_ahead", "clearance"}
        if unknown:
            raise SimulationConfigError(f"unknown keys in simulation.scene: {sorted(unknown)}",
                                        item=sorted(unknown)[0])
        objects = cls().objects if "objects" not in section else {}
        for key, body in (section.get("objects") or {}).items():
            if isinstance(key, bool) or not isinstance(key, int) or not isinstance(body, str):
                raise SimulationConfigError("simulation.scene.objects maps integer template ids to model "
                                            f"body names, got {key!r}: {body!r}", item=str(key))
            objects[key] = body
        reach = section.get("reach", cls.reach)
        if isinstance(reach, bool) or not isinstance(reach, (int, float)) or not reach > 0:
            raise SimulationConfigError(f"simulation.scene.reach must be a positive number, got {reach!r}",
                                        item="scene.reach")
        clearance = section.get("clearance", cls.clearance)
        if isinstance(clearance, bool) or not isinstance(clearance, (int, float)) or not clearance >= 0:
            raise SimulationConfigError(f"simulation.scene.clearance must be a number >= 0, got {clearance!r}",
                                        item="scene.clearance")
        look_ahead = section.get("look_ahead", cls.look_ahead)
        if not isinstance(look_ahead, bool):
            raise SimulationConfigError(f"simulation.scene.look_ahead must be true or false, got {look_ahead!r}",
                                        item="scene.look_ahead")
        return cls(objects=objects, reach=float(reach), look_ahead=look_ahead, clearance=float(clearance))


@dataclass(frozen=True)
class SimulationConfig:
    """The ``simulation:`` section (see the module docstring for the schema)."""

    initial_mode: Optional[str] = None
    timestep: float = 0.002
    control_period: float = 0.01
    real_time_factor: float = 0.0
    seed: int = 0
    fault_delay: float = 0.1
    settle: SettleConfig = SettleConfig()
    min_pelvis_height: float = 0.45
    max_torso_tilt_deg: float = 40.0
    modes: Dict[str, Dict[str, Any]] = field(default_factory=dict)
    actions: Dict[str, Dict[str, Any]] = field(default_factory=dict)
    invalidations: Dict[str, Tuple[str, ...]] = field(default_factory=dict)
    scenario: ScenarioConfig = ScenarioConfig()
    scene: SceneConfig = SceneConfig()
    faults: Dict[str, Dict[str, Any]] = field(default_factory=dict)
    stand_in: Optional[str] = None

    @classmethod
    def from_dict(cls, section: object) -> "SimulationConfig":
        if section is not None and not isinstance(section, Mapping):  # a file's section, as read
            raise SimulationConfigError(f"the simulation section must be a mapping, got {section!r}",
                                        item="simulation")
        section = dict(section or {})
        unknown = set(section) - _SIMULATION_KEYS
        if unknown:
            raise SimulationConfigError(f"unknown keys in simulation section: {sorted(unknown)}",
                                        item=sorted(unknown)[0])
        settle = SettleConfig(**(section.get("settle") or {}))
        fall = section.get("fall") or {}
        scenario_section = section.get("scenario") or {}
        scenario = ScenarioConfig(
            operator_inputs={str(k): bool(v) for k, v in (scenario_section.get("operator_inputs") or {}).items()},
            operator_answers={str(k): v for k, v in (scenario_section.get("operator_answers") or {}).items()},
            sensors={str(k): bool(v) for k, v in (scenario_section.get("sensors") or {}).items()},
        )
        return cls(
            initial_mode=section.get("initial_mode"),
            timestep=float(section.get("timestep", cls.timestep)),
            control_period=float(section.get("control_period", cls.control_period)),
            real_time_factor=float(section.get("real_time_factor", cls.real_time_factor)),
            seed=int(section.get("seed", cls.seed)),
            fault_delay=float(section.get("fault_delay", cls.fault_delay)),
            settle=settle,
            min_pelvis_height=float(fall.get("min_pelvis_height", cls.min_pelvis_height)),
            max_torso_tilt_deg=float(fall.get("max_torso_tilt_deg", cls.max_torso_tilt_deg)),
            modes={str(k): dict(v or {}) for k, v in (section.get("modes") or {}).items()},
            actions={str(k): dict(v or {}) for k, v in (section.get("actions") or {}).items()},
            invalidations={str(k): tuple(v or ()) for k, v in (section.get("invalidations") or {}).items()},
            scenario=scenario,
            scene=SceneConfig.from_dict(section.get("scene")),
            faults={str(k): dict(v or {}) for k, v in (section.get("faults") or {}).items()},
            stand_in=str(section["stand_in"]) if section.get("stand_in") else None,
        )


_SIMULATION_KEYS = {
    "initial_mode", "timestep", "control_period", "real_time_factor", "seed", "fault_delay",
    "settle", "fall", "modes", "actions", "invalidations", "scenario", "scene", "faults", "stand_in",
}


@dataclass(frozen=True)
class SystemConfig:
    """A robot system: its name, discrete abstraction and simulation settings."""

    system: str
    abstraction: RobotAbstraction
    simulation: SimulationConfig

    @classmethod
    def of(cls, system: RobotSystem) -> "SystemConfig":
        """The system's abstraction and ``simulation:`` section (defaults when it has none)."""
        return cls(system=system.name, abstraction=system.required_abstraction(),
                   simulation=SimulationConfig.from_dict(system.sections.get("simulation")))

    @classmethod
    def from_dict(cls, document: Mapping[str, Any]) -> "SystemConfig":
        """A system file's content held in memory (e.g. a variant of config/atlas.yaml in a test),
        named by its ``system:`` key."""
        name = str(document.get("system", "unnamed"))
        return cls.of(RobotSystem(name, Path(f"{name}.yaml"), abstraction=abstraction_from_document(document, name),
                                  sections=dict(document)))


def load_system_config(path: Path | str = DEFAULT_CONFIG) -> SystemConfig:
    """The configuration of the robot-system YAML file ``path``."""
    return SystemConfig.of(robot_system_from_file(path))
