"""atlas_sim: a MuJoCo humanoid that emulates ATLAS for synthesized behaviors.

The simulator executes the *capabilities* of a robot-system config
(``config/atlas.yaml``): control modes (``stand_prep``, ``stand``,
``manipulate``, ``step``, ``walk``) and actions (``look_down``,
``pickup_object``, ``object_template``, ...).  Each request ends with outcome
``completed`` or ``failed`` plus a reason, following the config's discrete
abstraction (mode transition system, action preconditions) and the
``simulation:`` section (motions, scenario, faults).  ROS-free.

Modules (MuJoCo is imported only by ``physics``, ``simulator``, ``rendering``)
------------------------------------------------------------------------------
``config``      ``load_system_config(path) -> SystemConfig`` (abstraction +
                simulation sections; the schema is documented there).
``discrete``    ``DiscreteState``, ``DiscreteSemantics``: the
                mode/precondition/validity rules, testable without physics.
``faults``      ``FaultSpec(always, fail_first, probability)``, ``FaultInjector``.
``kinematics``  joint groups, arm poses, whole-body ``POSTURES``, leg IK.
``motions``     ``build_motion(entry, geometry)``: posture, gait, head_tilt,
                arm_sequence, compute, operator_input.
``physics``     ``HumanoidPhysics``: model loading, targets, fall detection.
``simulator``   ``AtlasSimulator``, ``Request``, ``RequestResult``.
``operator_data`` the data operator inputs provide (template id, target pose) and its checks.
``rendering``   ``FrameRenderer``, ``KeyFrameRecorder``, ``save_png``.
``robot``       the ``Robot`` protocol, ``SimulatedRobot``, ``make_simulator``, ``parse_faults``.
``machine``     a StateInstantiation list as a validated tree (``load_machine``).
``executor``    runs a synthesized state machine on a robot (``execute_state_machine``).
``trace_check`` checks an executed trace against the specification and the goal order.
``closed_loop`` ``run_and_check``: execute, record key frames, check, draw the timeline.

Typical use
-----------
::

    from atlas_sim import AtlasSimulator, FaultSpec

    sim = AtlasSimulator()                    # config/atlas.yaml, mode stand_prep
    sim.execute("stand")                      # -> RequestResult(outcome="completed", ...)
    sim.execute("pickup_object").reason       # 'preconditions of pickup_object not met: ...'

    # Step-by-step driving, as a state-machine executor does:
    requests = sim.start_concurrently(["manipulate", "object_template"])
    while not all(r.done for r in requests):
        sim.step()                            # one control period (0.01 s sim time)
        print(sim.snapshot())                 # mode, completed actions, head tilt, ...
    outcomes = {r.name: r.result.outcome for r in requests}

    sim.inject_fault("pickup_object", FaultSpec(fail_first=1))
    sim.has_fallen()

``AtlasSimulator`` API
----------------------
``AtlasSimulator(config=None, model_path=MODEL_PATH)``  config: SystemConfig, path or None.
``start(name) -> Request``                      start one request (may be failed already).
``start_concurrently(names) -> [Request]``      start several; checks use the state before.
``step(duration=None) -> [RequestResult]``      advance one control period (or duration).
``poll(request) -> RequestResult | None``       result once finished.
``execute(name, timeout=60) -> RequestResult``  start and step until finished.
``execute_concurrently(names, timeout=60) -> {name: RequestResult}``.
``run_until_idle(timeout=60)``, ``hold(seconds)``  let sim time pass.
``snapshot() -> dict``                          time, mode, pending_mode, completed_actions,
                                                running, head_tilt, base_xy, base_yaw,
                                                pelvis_height, arm_pose, gripper_closed,
                                                holding_object, sensors, fallen.
``RequestResult``: name, outcome, reason, started_at, finished_at, completed,
                proposition ("stand_c" / "look_down_f").
``has_fallen() -> bool``, ``mode``, ``time``, ``completed_actions()``, ``head_tilt()``.
``inject_fault(name, FaultSpec | None)``, ``set_operator_input(name, bool)``,
``set_sensor(name, bool)``, ``push(force, duration, body="torso")``.
``add_listener(fn(event, request))`` / ``remove_listener(fn)``; events "started"/"finished".
``reset()``                                     back to the initial mode, counters cleared.
``physics`` (HumanoidPhysics), ``state`` (DiscreteState), ``outputs`` (dict),
``history`` (all RequestResults in finishing order).

Requests cannot be cancelled: a running request always ends with its own
outcome (an executor that no longer needs it simply ignores the result).
"""

from __future__ import annotations

import importlib

# Lazy exports keep ``import atlas_sim.discrete`` free of the MuJoCo import.
_EXPORTS = {
    "AtlasSimulator": "simulator",
    "Request": "simulator",
    "RequestResult": "simulator",
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
        raise AttributeError(f"module 'atlas_sim' has no attribute {name!r}")
    return getattr(importlib.import_module(f".{module_name}", __name__), name)
