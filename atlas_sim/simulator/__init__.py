"""atlas_sim.simulator: a MuJoCo humanoid that emulates ATLAS for synthesized behaviors.

The simulator executes the *capabilities* of a robot-system config
(``config/atlas.yaml``): control modes (``stand_prep``, ``stand``,
``manipulate``, ``step``, ``walk``) and actions (``look_down``,
``pickup_object``, ``object_template``, ...).  Each request ends with outcome
``completed`` or ``failed`` plus a reason, following the config's discrete
abstraction (mode transition system, action preconditions) and the
``simulation:`` section (motions, scenario, faults).  ROS-free.

Modules (MuJoCo is imported only by ``physics``, ``atlas_simulator``, ``rendering``)
------------------------------------------------------------------------------------
``config``      ``SystemConfig.of(robot_system)``, ``load_system_config(path)`` (abstraction +
                simulation sections; the schema is documented there).
``discrete``    ``DiscreteState``, ``DiscreteSemantics``: the
                mode/precondition/validity rules, testable without physics.
``faults``      ``FaultSpec(always, fail_first, probability)``, ``FaultInjector``.
``kinematics``  joint groups, arm poses, whole-body ``POSTURES``, leg IK.
``motions``     ``build_motion(entry, geometry)``: posture, gait, head_tilt,
                arm_sequence, compute, operator_input.
``physics``     ``HumanoidPhysics``: model loading, targets, fall detection.
``atlas_simulator`` ``AtlasSimulator``, ``Request``, ``RequestResult``.
``operator_data`` the data operator inputs provide (template id, target pose) and its checks.
``rendering``   ``FrameRenderer``, ``KeyFrameRecorder`` (key moments and motion frames), ``save_png``.
``factory``     ``make_simulator``, ``parse_faults``.
``node_names``  the ROS names the simulator node serves it under (shared with the FlexBE states).

How to drive the simulator from Python: docs/simulation.md, "The simulator from Python".
"""

from __future__ import annotations

import importlib

# Lazy exports keep ``import atlas_sim.simulator.discrete`` free of the MuJoCo import.
_EXPORTS = {
    "AtlasSimulator": "atlas_simulator",
    "Request": "atlas_simulator",
    "RequestResult": "atlas_simulator",
    "HumanoidPhysics": "physics",
    "MODEL_PATH": "physics",
    "FrameRenderer": "rendering",
    "KeyFrameRecorder": "rendering",
    "save_png": "rendering",
    "FaultSpec": "faults",
    "FaultInjector": "faults",
    "DiscreteSemantics": "discrete",
    "DiscreteState": "discrete",
    "SystemConfig": "config",
    "load_system_config": "config",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module_name = _EXPORTS.get(name)
    if module_name is None:
        raise AttributeError(f"module 'atlas_sim.simulator' has no attribute {name!r}")
    return getattr(importlib.import_module(f".{module_name}", __name__), name)
