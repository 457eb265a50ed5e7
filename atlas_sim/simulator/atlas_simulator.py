"""The simulator: requests for capabilities, run on the MuJoCo humanoid.

A *request* names one capability of the robot config (a control mode such as
``stand`` or an action such as ``look_down``).  Its lifecycle:

1. ``start(name, data)`` checks, in order: the robot has not fallen; the data
   the request carries (or the simulator's own operator answers) is valid and the
   object it names is within reach (``atlas_sim.simulator.operator_data``); the discrete
   rules allow it (``DiscreteSemantics.refusal``); its motion's joint groups
   are free.  A refused request is finished at once with outcome ``failed``
   and does not change the discrete state.  Otherwise the request *runs*; an
   injected fault or a missing operator input makes it fail later (after
   ``fault_delay`` resp. the input's duration) without moving the robot.
2. ``step()`` advances physics by one control period and updates every
   running motion.  A motion completes when its trajectory has ended and the
   joints it owns have settled (tracking error and speed within tolerance,
   base at rest); it fails if it has not settled ``settle.timeout`` seconds
   after the trajectory ended, or if the robot falls.
3. The result (:class:`RequestResult`: outcome ``completed``/``failed`` and a
   reason) is stored on the :class:`Request` and reported to listeners.

Several requests may run at once when their motions use disjoint joint
groups (e.g. ``object_template`` with a mode change, or ``look_down`` with
``manipulate``), which is how a synthesized state machine activates them.
"""

from __future__ import annotations

import itertools
import time as wallclock
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Union

import numpy as np

from .config import SimulationConfigError, SystemConfig, load_system_config
from .discrete import COMPLETED, FAILED, DiscreteSemantics, DiscreteState
from .faults import FaultInjector, FaultSpec
from .kinematics import POSTURES
from .operator_data import TEMPLATE_ID, datum_refusal, operator_answer, provided_datum
from .motions import (
    DEFAULT_ACTION_ENTRY,
    DEFAULT_MODE_ENTRY,
    GaitMotion,
    Motion,
    OperatorInputMotion,
    build_motion,
)
from .physics import MODEL_PATH, FallCriteria, HumanoidPhysics


@dataclass(frozen=True)
class Incident:
    """Something physical that should not happen: the robot touched furniture with its body
    (``kind`` ``contact``; ``part`` and ``obstacle`` are the bodies) or fell (``fall``).

    Runs carry them into their trace (``Trace.incidents``), where the trace check reports
    each as a violation: a run that went through a table is not a correct run."""

    kind: str
    time: float
    message: str
    part: str = ""
    obstacle: str = ""

    def to_dict(self) -> Dict[str, Any]:
        return {"kind": self.kind, "time": round(self.time, 4), "message": self.message,
                "part": self.part, "obstacle": self.obstacle}


@dataclass(frozen=True)
class RequestResult:
    """Final outcome of one request."""

    name: str
    outcome: str  # "completed" or "failed"
    reason: str
    started_at: float
    finished_at: float

    @property
    def completed(self) -> bool:
        return self.outcome == COMPLETED

    @property
    def proposition(self) -> str:
        """Outcome proposition of the specification, e.g. ``stand_c`` or ``look_down_f``
        (suffix = first letter of the outcome, as in the abstraction config)."""
        return f"{self.name}_{self.outcome[0]}"


class Request:
    """Handle of a started request; ``result`` is set once it has finished."""

    def __init__(self, request_id: int, name: str, started_at: float, motion: Optional[Motion] = None):
        self.id = request_id
        self.name = name
        self.started_at = started_at
        self.motion = motion
        self.result: Optional[RequestResult] = None
        #: planned failure (injected fault, missing operator input): time and reason
        self.fail_at: Optional[float] = None
        self.fail_reason: str = ""

    @property
    def done(self) -> bool:
        return self.result is not None

    def __repr__(self) -> str:
        state = self.result.outcome if self.result else "running"
        return f"Request({self.id}, {self.name!r}, {state})"


Listener = Callable[[str, Request], None]


#: How far a walk may sidestep to pass beside furniture (m), and in what increments.
MAX_DETOUR = 1.0
DETOUR_STEP = 0.1


class AtlasSimulator:
    """Humanoid simulator with the discrete semantics of a robot config.

    ``config`` may be a :class:`SystemConfig`, a path to a YAML file, or None
    for ``config/atlas.yaml``.
    """

    def __init__(
        self,
        config: Union[SystemConfig, str, Path, None] = None,
        model_path: Path = MODEL_PATH,
    ) -> None:
        if not isinstance(config, SystemConfig):
            config = load_system_config(config) if config is not None else load_system_config()
        self.config = config
        self.settings = config.simulation
        self.abstraction = config.abstraction
        self.semantics = DiscreteSemantics(self.abstraction, self.settings.invalidations)
        self.physics = HumanoidPhysics(
            model_path,
            timestep=self.settings.timestep,
            fall_criteria=FallCriteria(self.settings.min_pelvis_height, self.settings.max_torso_tilt_deg),
        )
        self._substeps = max(1, round(self.settings.control_period / self.physics.timestep))
        #: input action -> the data kind it provides (e.g. object_template -> template_id)
        self.provides: Dict[str, str] = {
            name: kind for name, entry in self.settings.actions.items()
            if (kind := provided_datum(entry, name)) is not None}
        self._validate_settings()
        self._listeners: List[Listener] = []
        self.reset()

    # ------------------------------------------------------------------ setup
    def _validate_settings(self) -> None:
        """Fail early on names or motion entries the simulator cannot use."""
        settings = self.settings
        named: Dict[str, Iterable[str]] = {
            "modes": settings.modes,
            "actions": settings.actions,
            "faults": settings.faults,
            "scenario.operator_inputs": settings.scenario.operator_inputs,
        }
        for section, entries in named.items():
            unknown = [name for name in entries if not self.abstraction.is_capability(name)]
            if unknown:
                raise SimulationConfigError(f"simulation.{section} names unknown capabilities {unknown}",
                                            item=unknown[0])
        misplaced = [m for m in settings.modes if not self.abstraction.is_mode(m)]
        misplaced += [a for a in settings.actions if not self.abstraction.is_action(a)]
        if misplaced:
            raise SimulationConfigError(f"modes/actions listed in the wrong simulation section: {misplaced}",
                                        item=misplaced[0])
        for name in self.abstraction.capabilities:
            self._motion_for(name)  # raises on unknown motion kinds, poses or parameters
        for entry in settings.faults.values():
            FaultSpec.from_dict(entry)
        for body in settings.scene.objects.values():
            self.physics.body_position(body)  # raises KeyError naming a body the model lacks
        for name, answer in settings.scenario.operator_answers.items():
            kind = self.provides.get(name)
            reason = datum_refusal(kind, answer, settings.scene) if kind else f"{name} provides no data"
            if reason:
                raise SimulationConfigError(f"simulation.scenario.operator_answers.{name}: {reason}", item=name)

    def reset(self) -> None:
        """Back to the initial mode at rest, forgetting completions and fault counters."""
        initial_mode = self.settings.initial_mode or self.config.abstraction.initial_mode
        self.state: DiscreteState = self.semantics.initial_state(initial_mode)
        self.physics.reset_to_posture(self._posture_of_mode(self.state.mode))
        self.faults = FaultInjector(
            self.settings.seed,
            {name: FaultSpec.from_dict(entry) for name, entry in self.settings.faults.items()},
        )
        self.operator_inputs: Dict[str, bool] = dict(self.settings.scenario.operator_inputs)
        #: data kind -> what the simulator's own operator answered (input actions run here)
        self.answers: Dict[str, Any] = {}
        self.sensors: Dict[str, bool] = {s: False for s in self.abstraction.sensors}
        self.sensors.update(self.settings.scenario.sensors)
        posture = POSTURES[self._posture_of_mode(self.state.mode)]
        self.outputs: Dict[str, Any] = {
            "arm_pose": posture.arm_pose,
            "gripper_closed": False,
            "holding_object": False,
        }
        self._running: List[Request] = []
        #: results of all finished requests, in finishing order (for timelines/logs)
        self.history: List[RequestResult] = []
        self._ids = itertools.count(1)
        self._fallen = False
        self._fall_reason = ""
        #: physical incidents, in order: the first contact of each robot part with each piece of
        #: furniture, and the fall
        self.incidents: List[Incident] = []
        self._touched: set = set()
        self._pace_anchor: Optional[tuple] = None
        self._push_until: Optional[tuple] = None

    def _posture_of_mode(self, mode: str) -> str:
        entry = self.settings.modes.get(mode, DEFAULT_MODE_ENTRY)
        return entry.get("posture", "stand") if entry.get("motion") == "posture" else "stand"

    def add_listener(self, listener: Listener) -> None:
        """Call ``listener(event, request)`` with event ``"started"`` or ``"finished"``."""
        self._listeners.append(listener)

    def remove_listener(self, listener: Listener) -> None:
        self._listeners.remove(listener)

    def inject_fault(self, capability: str, spec: Optional[FaultSpec]) -> None:
        """Install (``None``: remove) a fault for a capability at run time."""
        self._require_capability(capability)
        self.faults.set_fault(capability, spec)

    def set_operator_input(self, name: str, provided: bool) -> None:
        """Scenario: whether the operator answers the input action ``name``."""
        self._require_capability(name)
        self.operator_inputs[name] = provided

    def push(self, force, duration: float, body: str = "torso") -> None:
        """Disturbance: apply a world-frame force (N) to a body for ``duration`` s."""
        self.physics.set_external_force(body, force)
        self._push_until = (body, self.time + duration)

    def set_sensor(self, name: str, value: bool) -> None:
        self.sensors[name] = bool(value)

    def _require_capability(self, name: str) -> None:
        if not self.abstraction.is_capability(name):
            raise KeyError(f"unknown capability {name!r}")

    # -------------------------------------------------------------- requests
    def start(self, name: str, data: Optional[Mapping[str, Any]] = None) -> Request:
        """Start a request; returns its handle (possibly already failed).

        ``data``: the userdata that reached the request (e.g. ``{"template_id": 1}``); None
        means the request carries none and the simulator's own operator answers count.
        """
        return self._start(name, self._refusal(name, data))

    def start_concurrently(self, names: Iterable[str],
                           data: Optional[Mapping[str, Mapping[str, Any]]] = None) -> List[Request]:
        """Start several requests in one instant.

        The discrete checks of all of them use the state *before* any of them
        starts (a state machine activates them together), so e.g. ``look_down``
        (needs ``stand``) and ``manipulate`` may start together from ``stand``
        in either order.  Joint-group conflicts are still checked one by one.
        """
        names = list(names)
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate names in {names}")
        data = data or {}
        refusals = [self._refusal(name, data.get(name)) for name in names]
        return [self._start(name, refusal) for name, refusal in zip(names, refusals)]

    def _refusal(self, name: str, data: Optional[Mapping[str, Any]] = None) -> Optional[str]:
        if self._fall_reason:
            return f"robot has fallen: {self._fall_reason}"
        needs = self.needed_data(name)
        values: Mapping[str, Any]
        if data is None:  # the in-process operator: input actions ran on the simulator
            refusal = self.semantics.refusal(self.state, name)
            values = self.answers
        else:
            for precondition, kind in needs.items():
                if kind not in data:
                    return f"{name} needs {kind} (what {precondition} provides); the request carries none"
                reason = datum_refusal(kind, data[kind], self.settings.scene)
                if reason:
                    return f"{name}: {reason}"
            refusal = self.semantics.refusal(self.state, name, exempt=needs)
            values = data
        if refusal is None and TEMPLATE_ID in needs.values() and TEMPLATE_ID in values:
            refusal = self._reach_refusal(name, values[TEMPLATE_ID])
        return refusal

    def needed_data(self, name: str) -> Dict[str, str]:
        """Input action -> data kind, for the input actions among ``name``'s preconditions."""
        preconditions = self.abstraction.actions.get(name, ())
        return {p: self.provides[p] for p in preconditions if p in self.provides}

    def _reach_refusal(self, name: str, template_id: int) -> Optional[str]:
        """An action that moves the arms on an object needs the object within reach."""
        entry = self.settings.actions.get(name, {})
        if entry.get("motion") != "arm_sequence":
            return None
        body = self.settings.scene.objects[template_id]
        offset = self.physics.body_position(body)[:2] - self.physics.pelvis_position()[:2]
        distance = float(np.hypot(*offset))
        if distance > self.settings.scene.reach:
            return (f"object {template_id} ({body}) is {distance:.2f} m away, beyond reach "
                    f"({self.settings.scene.reach:g} m)")
        return None

    def _start(self, name: str, refusal: Optional[str]) -> Request:
        now = self.time
        motion = None if refusal else self._motion_for(name)
        if motion is not None:
            refusal = self._busy_reason(motion) or self._path_refusal(name, motion)
        request = Request(next(self._ids), name, now, motion)
        if refusal:
            request.result = RequestResult(name, FAILED, refusal, now, now)
            self.history.append(request.result)
            self._notify("started", request)
            self._notify("finished", request)
            return request

        self.semantics.begin(self.state, name)
        fault = self.faults.fault_for_attempt(name)
        if fault:
            self._plan_failure(request, now + self.settings.fault_delay, fault)
        elif isinstance(motion, OperatorInputMotion) and not self.operator_inputs.get(name, False):
            self._plan_failure(request, now + motion.duration, f"operator did not provide {name}")
        else:
            assert motion is not None  # a request without a motion was refused above
            motion.start(self.physics)
        self._running.append(request)
        self._notify("started", request)
        return request

    def _motion_for(self, name: str) -> Motion:
        if self.abstraction.is_mode(name):
            entry = self.settings.modes.get(name, DEFAULT_MODE_ENTRY)
        else:
            entry = self.settings.actions.get(name, DEFAULT_ACTION_ENTRY)
        return build_motion(entry, self.physics.geometry)

    def _busy_reason(self, motion: Motion) -> Optional[str]:
        for other in self._running:
            assert other.motion is not None  # every running request has one (_start)
            shared = motion.groups & other.motion.groups
            if shared:  # requests planned to fail hold an empty motion, so no groups
                return f"busy: {', '.join(sorted(shared))} used by {other.name}"
        return None

    def _path_refusal(self, name: str, motion: Motion) -> Optional[str]:
        """Plan a walk around furniture in its way; why it cannot go (None: it can).

        A walk whose straight way comes within ``scene.clearance`` of furniture first sidesteps
        (left and right in turn, 0.1 m more each time, up to ``MAX_DETOUR``) to where both the
        sidestep and the walk on are free; when no such detour exists it fails, naming the
        furniture (the robot must never walk into it)."""
        scene = self.settings.scene
        if motion.advance <= 0 or not scene.look_ahead:
            return None
        obstacle = self.physics.obstacle_ahead(motion.advance, scene.clearance)
        if obstacle is None:
            return None
        for tenths in range(1, round(MAX_DETOUR / DETOUR_STEP) + 1):
            for side in (1, -1):
                detour = side * tenths * DETOUR_STEP
                # a sidestep keeps the gap the robot has ahead: only what is beside it counts
                sideways = self.physics.obstacle_ahead(abs(detour), scene.clearance, turn=side * np.pi / 2,
                                                       side_margin=0.0)
                if sideways is None and self.physics.obstacle_ahead(motion.advance, scene.clearance,
                                                                    shift=detour) is None:
                    assert isinstance(motion, GaitMotion)  # the motion that advances
                    motion.plan_detour(detour)
                    return None
        return (f"{name}: the way is blocked by {obstacle.body} ({obstacle.free_distance:.2f} m free ahead, "
                f"the walk needs {motion.advance:.2f} m and {scene.clearance:.2f} m clearance; no detour "
                f"within {MAX_DETOUR:.1f} m to either side)")

    @staticmethod
    def _plan_failure(request: Request, when: float, reason: str) -> None:
        request.fail_at = when
        request.fail_reason = reason
        # A request that will fail does not move the robot nor claim joints.
        request.motion = Motion(0.0)

    def poll(self, request: Request) -> Optional[RequestResult]:
        """The result of a request, or None while it runs."""
        return request.result

    def step(self, duration: Optional[float] = None) -> List[RequestResult]:
        """Advance by one control period (or by ``duration`` seconds, rounded up
        to whole periods); returns the results of requests that finished."""
        periods = 1 if duration is None else max(1, int(np.ceil(duration / self.settings.control_period - 1e-9)))
        finished: List[RequestResult] = []
        for _ in range(periods):
            finished.extend(self._control_period())
        return finished

    def _control_period(self) -> List[RequestResult]:
        finished: List[RequestResult] = []
        for request in list(self._running):
            if request.fail_at is not None and self.time >= request.fail_at - 1e-9:
                finished.append(self._finish(request, FAILED, request.fail_reason))
            else:
                assert request.motion is not None  # every running request has one (_start)
                request.motion.update(self.physics, self.time - request.started_at)
        self.physics.step(self._substeps)
        if self._push_until and self.time >= self._push_until[1] - 1e-9:
            self.physics.set_external_force(self._push_until[0], (0.0, 0.0, 0.0))
            self._push_until = None
        self._record_contacts()
        if not self._fallen and self.physics.has_fallen():
            self._fallen = True
            self._fall_reason = self.physics.fall_reason()
            self.incidents.append(Incident("fall", self.time, self._fall_reason))
        for request in list(self._running):
            if self._fallen:
                finished.append(self._finish(request, FAILED, self._fall_reason))
            elif request.fail_at is None:
                result = self._check_settled(request)
                if result:
                    finished.append(result)
        if self.outputs["holding_object"]:  # after the results: a pickup that just completed holds it
            self.physics.carry_object()
        self._pace()
        return finished

    def _record_contacts(self) -> None:
        """An incident for the first contact of each robot part with each piece of furniture."""
        for part, obstacle in self.physics.obstacle_contacts():
            if (part, obstacle) in self._touched:
                continue
            self._touched.add((part, obstacle))
            running = ", ".join(r.name for r in self._running) or "no request"
            self.incidents.append(Incident(
                "contact", self.time, f"the robot's {part} ran into {obstacle} (during {running})", part, obstacle))

    def _check_settled(self, request: Request) -> Optional[RequestResult]:
        motion = request.motion
        assert motion is not None  # every running request has one (_start)
        elapsed = self.time - request.started_at
        if elapsed < motion.duration:
            return None
        if self._motion_settled(motion):
            return self._finish(request, COMPLETED, f"{request.name} completed")
        if elapsed > motion.duration + self.settings.settle.timeout:
            return self._finish(request, FAILED, f"{request.name} did not settle in time")
        return None

    def _motion_settled(self, motion: Motion) -> bool:
        tolerance = self.settings.settle
        joints = motion.settle_joints
        if joints:
            targets = self.physics.targets(joints)
            positions = self.physics.joint_positions(joints)
            if max(abs(positions[j] - targets[j]) for j in joints) > tolerance.position_tolerance:
                return False
            if np.max(np.abs(self.physics.joint_speeds(joints))) > tolerance.velocity_tolerance:
                return False
        if motion.moves_base and self.physics.pelvis_speed() > tolerance.velocity_tolerance:
            return False
        return True

    def _finish(self, request: Request, outcome: str, reason: str) -> RequestResult:
        self._running.remove(request)
        assert request.motion is not None  # every running request has one (_start)
        request.motion.stop(self.physics)
        self.semantics.finish(self.state, request.name, outcome)
        if outcome == COMPLETED:
            self.outputs.update(request.motion.effects)
            if request.name in self.provides:
                kind = self.provides[request.name]
                self.answers[kind] = operator_answer(self.settings, request.name, kind)
        request.result = RequestResult(request.name, outcome, reason, request.started_at, self.time)
        self.history.append(request.result)
        self._notify("finished", request)
        return request.result

    def _notify(self, event: str, request: Request) -> None:
        for listener in self._listeners:
            listener(event, request)

    def _pace(self) -> None:
        """Sleep to keep sim time at ``real_time_factor`` x wall time (0: no pacing)."""
        factor = self.settings.real_time_factor
        if factor <= 0:
            return
        if self._pace_anchor is None:
            self._pace_anchor = (wallclock.monotonic(), self.time)
        wall0, sim0 = self._pace_anchor
        delay = wall0 + (self.time - sim0) / factor - wallclock.monotonic()
        if delay > 0:
            wallclock.sleep(delay)

    # ------------------------------------------------------ blocking helpers
    def run_until_idle(self, timeout: float = 60.0) -> List[RequestResult]:
        """Step until no request runs (or ``timeout`` sim seconds passed)."""
        deadline = self.time + timeout
        finished: List[RequestResult] = []
        while self._running and self.time < deadline:
            finished.extend(self.step())
        return finished

    def execute(self, name: str, timeout: float = 60.0) -> RequestResult:
        """Start one request and step until it has finished."""
        return self.execute_concurrently([name], timeout)[name]

    def execute_concurrently(self, names: Iterable[str], timeout: float = 60.0) -> Dict[str, RequestResult]:
        """``start_concurrently`` and step until all finished; results by name."""
        requests = self.start_concurrently(names)
        deadline = self.time + timeout
        while not all(r.done for r in requests) and self.time < deadline:
            self.step()
        if not all(r.done for r in requests):
            raise TimeoutError(f"requests still running after {timeout} s: {requests}")
        return {r.name: r.result for r in requests if r.result is not None}  # all done: every one

    def hold(self, seconds: float) -> List[RequestResult]:
        """Let time pass (running requests continue)."""
        return self.step(seconds)

    # ----------------------------------------------------------------- state
    @property
    def time(self) -> float:
        return self.physics.time

    @property
    def mode(self) -> str:
        return self.state.mode

    @property
    def running(self) -> List[Request]:
        return list(self._running)

    @property
    def idle(self) -> bool:
        return not self._running

    def completed_actions(self) -> List[str]:
        return self.state.completed_actions()

    def has_fallen(self) -> bool:
        """True once the robot has fallen (sticky until ``reset``)."""
        return self._fallen or self.physics.has_fallen()

    def head_tilt(self) -> float:
        """Measured neck pitch in radians (positive looks down)."""
        return self.physics.joint_positions(["neck_pitch"])["neck_pitch"]

    def snapshot(self) -> Dict[str, Any]:
        """Plain-Python summary of the robot state (e.g. for a ROS topic)."""
        pelvis = self.physics.pelvis_position()
        return {
            "time": round(self.time, 6),
            "mode": self.state.mode,
            "pending_mode": self.state.pending_mode,
            "completed_actions": self.completed_actions(),
            "running": [r.name for r in self._running],
            "head_tilt": self.head_tilt(),
            "base_xy": [float(pelvis[0]), float(pelvis[1])],
            "base_yaw": self.physics.pelvis_yaw(),
            "pelvis_height": float(pelvis[2]),
            "arm_pose": self.outputs["arm_pose"],
            "gripper_closed": bool(self.outputs["gripper_closed"]),
            "holding_object": bool(self.outputs["holding_object"]),
            "sensors": dict(self.sensors),
            "fallen": self.has_fallen(),
        }
