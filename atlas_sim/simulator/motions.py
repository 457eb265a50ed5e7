"""Motions: time-parametrised joint targets that carry out one capability.

A motion claims joint *groups* (see ``kinematics.JOINT_GROUPS``, plus
``"base"`` for motions that move the floating base); the simulator refuses to
run two motions with a common group at once.  Each control period the
simulator calls ``update(physics, elapsed)``; once ``elapsed >= duration`` it
waits until the joints in ``settle_joints`` track their targets and stop
moving, then applies ``effects`` to the simulator outputs.

Motion kinds, selected by ``motion:`` in the ``simulation:`` config section:

==============  ===============================================================
posture         whole-body posture (``posture``: crouch | stand | manipulate)
gait            stepping/walking with the balance-assist weld (``steps``,
                ``step_length``; step_length 0 steps in place)
head_tilt       neck pitch to ``tilt_deg`` (positive looks down)
arm_sequence    arm/gripper keyframes ``[{arms: <pose>, gripper: open|closed,
                duration: s}, ...]``, ``holds_object: true`` if it ends holding
compute         no motion, just ``duration`` (planning steps)
operator_input  no motion; completes iff the scenario provides the input
==============  ===============================================================

``physics`` is duck-typed (see ``atlas_sim.simulator.physics.HumanoidPhysics``), so this
module needs numpy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Dict, FrozenSet, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from .config import SimulationConfigError
from .kinematics import (
    ARM_POSES,
    HIP_HEIGHTS,
    JOINT_GROUPS,
    POSTURES,
    SIDES,
    JointTargets,
    LegGeometry,
    arm_targets,
    gripper_targets,
    sagittal_leg_ik,
)

BASE_GROUP = "base"


def minimum_jerk(fraction: float) -> float:
    """Smooth 0..1 profile with zero velocity and acceleration at both ends."""
    s = min(1.0, max(0.0, fraction))
    return s**3 * (10.0 - 15.0 * s + 6.0 * s * s)


def joints_of(groups) -> Tuple[str, ...]:
    return tuple(j for g in groups if g != BASE_GROUP for j in JOINT_GROUPS[g])


class Motion:
    """Base class: a motion that does nothing for ``duration`` seconds."""

    kind = "compute"

    def __init__(self, duration: float, groups=(), effects: Optional[Mapping[str, Any]] = None):
        self.duration = float(duration)
        self.groups: FrozenSet[str] = frozenset(groups)
        self.effects: Dict[str, Any] = dict(effects or {})

    @property
    def settle_joints(self) -> Tuple[str, ...]:
        """Joints that must track their targets before the motion counts as settled."""
        return joints_of(self.groups)

    @property
    def advance(self) -> float:
        """How far (m) the motion carries the robot along its heading (0: it stays put)."""
        return 0.0

    @property
    def moves_base(self) -> bool:
        """Whether the floating base must come to rest before the motion settles."""
        return bool(self.groups & {"legs", BASE_GROUP})

    def start(self, physics) -> None:
        """Called once when the request starts."""

    def update(self, physics, elapsed: float) -> None:
        """Set targets for ``elapsed`` seconds after the start."""

    def stop(self, physics) -> None:
        """Called once when the request ends (completed, failed or aborted)."""


class OperatorInputMotion(Motion):
    """Waits for an operator input; the simulator decides from the scenario
    whether the input arrives."""

    kind = "operator_input"


class KeyframeMotion(Motion):
    """Moves joints through keyframes with minimum-jerk interpolation.

    Each keyframe is ``(duration, targets)``; joints not named in a keyframe
    keep the value of the previous keyframe (or their target at start).
    """

    kind = "keyframes"

    def __init__(self, keyframes: Sequence[Tuple[float, JointTargets]], groups, effects=None):
        super().__init__(sum(d for d, _ in keyframes), groups, effects)
        self.keyframes = [(float(d), dict(t)) for d, t in keyframes]
        self._waypoints: List[JointTargets] = []

    def start(self, physics) -> None:
        joints = sorted({j for _, targets in self.keyframes for j in targets})
        current = physics.targets(joints)
        self._waypoints = [current]
        for _, targets in self.keyframes:
            self._waypoints.append({**self._waypoints[-1], **targets})

    def update(self, physics, elapsed: float) -> None:
        segment_start = 0.0
        for index, (duration, _) in enumerate(self.keyframes):
            last = index == len(self.keyframes) - 1
            if elapsed < segment_start + duration or last:
                fraction = (elapsed - segment_start) / duration if duration > 0 else 1.0
                physics.set_targets(self._blend(index, minimum_jerk(fraction)))
                return
            segment_start += duration

    def _blend(self, index: int, weight: float) -> JointTargets:
        before, after = self._waypoints[index], self._waypoints[index + 1]
        return {j: before[j] + weight * (after[j] - before[j]) for j in after}


@dataclass(frozen=True)
class _GaitPhase:
    """One phase of a gait: the pelvis moves between two (forward, lateral, height) points while
    at most one foot swings between two (forward, lateral) footholds."""

    duration: float
    pelvis_from: Tuple[float, float, float]
    pelvis_to: Tuple[float, float, float]
    swing_side: Optional[str] = None
    foot_from: Tuple[float, float] = (0.0, 0.0)
    foot_to: Tuple[float, float] = (0.0, 0.0)


class GaitMotion(Motion):
    """Steps (in place or forwards along the robot's heading), after sidesteps around furniture.

    The pelvis follows the planned path through the balance-assist weld; the
    legs get joint targets from inverse kinematics so that the stance foot
    stays put and the swing foot lifts and lands on its next foothold.  Feet
    land ``step_length / 2`` ahead of the pelvis, and a closing step brings the
    feet side by side, so the gait ends in the stand posture. A ``detour`` (metres to the
    left, negative: right; ``plan_detour``) first moves the robot sideways in steps of at most
    ``sidestep`` metres, the foot on that side leading, so the walk passes beside an obstacle.
    """

    kind = "gait"

    def __init__(
        self,
        geometry: LegGeometry,
        steps: int,
        step_length: float,
        step_duration: float = 0.7,
        swing_height: float = 0.06,
        transfer_duration: float = 0.5,
        walk_hip_height: float = HIP_HEIGHTS["walk"],
        final_hip_height: float = HIP_HEIGHTS["stand"],
        sidestep: float = 0.1,
    ):
        self.geometry = geometry
        self.steps = int(steps)
        self.step_length = float(step_length)
        self.step_duration = float(step_duration)
        self.swing_height = float(swing_height)
        self.transfer_duration = float(transfer_duration)
        self.walk_hip_height = float(walk_hip_height)
        self.final_hip_height = float(final_hip_height)
        self.sidestep = float(sidestep)
        self.detour = 0.0
        super().__init__(self._duration(), groups=("legs", "torso", BASE_GROUP))
        self._phases: List[_GaitPhase] = []

    def _sidesteps(self) -> int:
        return math.ceil(abs(self.detour) / self.sidestep - 1e-9) if self.detour else 0

    def _duration(self) -> float:
        closing = 1 if self.step_length != 0.0 else 0
        return 2 * self.transfer_duration + (2 * self._sidesteps() + self.steps + closing) * self.step_duration

    @property
    def advance(self) -> float:
        return self.steps * self.step_length

    def plan_detour(self, lateral: float) -> None:
        """Sidestep ``lateral`` metres (positive: left) before walking on (call before start)."""
        self.detour = float(lateral)
        self.duration = self._duration()

    def start(self, physics) -> None:
        pelvis = physics.pelvis_position()
        yaw = physics.pelvis_yaw()
        self._origin = pelvis[:2].copy()
        self._heading = np.array([math.cos(yaw), math.sin(yaw)])
        self._left = np.array([-math.sin(yaw), math.cos(yaw)])
        self._yaw = yaw
        self._feet: Dict[str, Tuple[float, float]] = {}
        for side in SIDES:
            offset = physics.body_position(f"{side}_foot")[:2] - self._origin
            self._feet[side] = (float(offset @ self._heading), float(offset @ self._left))
        self._phases = self._plan(start_height=float(pelvis[2]))
        self._back_start = physics.targets(["back_pitch"])["back_pitch"]
        physics.set_balance_assist(True)

    def _plan(self, start_height: float) -> List[_GaitPhase]:
        walk_height = self.geometry.pelvis_height(self.walk_hip_height)
        final_height = self.geometry.pelvis_height(self.final_hip_height)
        feet = dict(self._feet)
        forward = 0.5 * (feet["left"][0] + feet["right"][0])
        lateral = 0.0
        phases = [_GaitPhase(self.transfer_duration, (0.0, 0.0, start_height), (forward, lateral, walk_height))]

        def swing(side, to, pelvis_to):
            nonlocal forward, lateral
            phases.append(_GaitPhase(self.step_duration, (forward, lateral, walk_height), pelvis_to + (walk_height,),
                                     side, feet[side], to))
            feet[side] = to
            forward, lateral = pelvis_to

        count = self._sidesteps()
        leading, trailing = ("left", "right") if self.detour > 0 else ("right", "left")
        for _ in range(count):
            shift = self.detour / count
            swing(leading, (feet[leading][0], feet[leading][1] + shift), (forward, lateral + shift / 2))
            swing(trailing, (feet[trailing][0], feet[trailing][1] + shift), (forward, lateral + shift / 2))
        for step in range(self.steps):
            side = SIDES[step % 2]
            target = forward + self.step_length
            last = step == self.steps - 1
            landing = target if (last or self.step_length == 0.0) else target + 0.5 * self.step_length
            swing(side, (landing, feet[side][1]), (target, lateral))
        if self.step_length != 0.0:
            side = SIDES[self.steps % 2]
            swing(side, (forward, feet[side][1]), (forward, lateral))
        phases.append(_GaitPhase(self.transfer_duration, (forward, lateral, walk_height),
                                 (forward, lateral, final_height)))
        self._final_feet = feet
        return phases

    def update(self, physics, elapsed: float) -> None:
        phase, fraction, feet = self._phase_at(elapsed)
        weight = minimum_jerk(fraction)
        forward, lateral, height = (start + weight * (end - start)
                                    for start, end in zip(phase.pelvis_from, phase.pelvis_to))
        lifts = {side: 0.0 for side in SIDES}
        if phase.swing_side is not None:
            feet[phase.swing_side] = tuple(start + weight * (end - start)
                                           for start, end in zip(phase.foot_from, phase.foot_to))
            lifts[phase.swing_side] = self.swing_height * math.sin(math.pi * fraction)
        position = np.append(self._origin + forward * self._heading + lateral * self._left, height)
        physics.move_pelvis_target(position, _yaw_quaternion(self._yaw))
        targets = {"back_pitch": self._back_start * (1.0 - minimum_jerk(elapsed / self.transfer_duration))}
        for side in SIDES:
            targets.update(self._leg_targets(side, feet[side][0] - forward, feet[side][1] - lateral,
                                             lifts[side], height))
        physics.set_targets(targets)

    def _phase_at(self, elapsed: float):
        """The active phase, the fraction done, and foot positions at its start."""
        feet = dict(self._feet)
        phase_start = 0.0
        for index, phase in enumerate(self._phases):
            if elapsed < phase_start + phase.duration or index == len(self._phases) - 1:
                return phase, (elapsed - phase_start) / phase.duration, feet
            if phase.swing_side is not None:
                feet[phase.swing_side] = phase.foot_to
            phase_start += phase.duration
        raise AssertionError("gait has no phases")

    def _leg_targets(self, side: str, forward: float, lateral_offset: float, lift: float,
                     pelvis_height: float) -> JointTargets:
        geometry = self.geometry
        mirror = 1.0 if side == "left" else -1.0
        lateral = lateral_offset - mirror * geometry.hip_offset_y
        down = pelvis_height + geometry.hip_offset_z - geometry.ankle_height - lift
        hip_roll = math.atan2(lateral, down)
        hip_pitch, knee, ankle_pitch = sagittal_leg_ik(geometry, forward, math.hypot(lateral, down))
        return {
            f"{side}_hip_yaw": 0.0,
            f"{side}_hip_roll": hip_roll,
            f"{side}_hip_pitch": hip_pitch,
            f"{side}_knee": knee,
            f"{side}_ankle_pitch": ankle_pitch,
            f"{side}_ankle_roll": -hip_roll,
        }

    def stop(self, physics) -> None:
        physics.set_balance_assist(False)


def _yaw_quaternion(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


# ------------------------------------------------------------------ factory
DEFAULT_MODE_ENTRY = {"motion": "posture", "posture": "stand"}
DEFAULT_ACTION_ENTRY = {"motion": "compute", "duration": 0.2}


def build_motion(entry: Mapping[str, Any], geometry: LegGeometry) -> Motion:
    """Create a fresh motion from one ``simulation.modes``/``actions`` entry."""
    entry = dict(entry)
    kind = entry.pop("motion", "compute")
    builder = _BUILDERS.get(kind)
    if builder is None:
        raise SimulationConfigError(f"unknown motion kind {kind!r}; known: {sorted(_BUILDERS)}", item=str(kind))
    return builder(entry, geometry)


def _posture(entry, geometry: LegGeometry) -> Motion:
    posture = POSTURES[entry.get("posture", "stand")]
    return KeyframeMotion(
        [(entry.get("duration", 1.5), posture.targets(geometry))],
        groups=("legs", "torso", "arms"),
        effects={"arm_pose": posture.arm_pose},
    )


def _gait(entry, geometry: LegGeometry) -> Motion:
    return GaitMotion(geometry, **entry)


def _head_tilt(entry, geometry: LegGeometry) -> Motion:
    tilt = math.radians(float(entry.get("tilt_deg", 45.0)))
    return KeyframeMotion([(entry.get("duration", 0.8), {"neck_pitch": tilt})], groups=("head",))


def _arm_sequence(entry, geometry: LegGeometry) -> Motion:
    keyframes = []
    for frame in entry["keyframes"]:
        if frame["arms"] not in ARM_POSES:
            raise SimulationConfigError(f"unknown arm pose {frame['arms']!r}; known: {sorted(ARM_POSES)}",
                                        item=str(frame["arms"]))
        targets = arm_targets(frame["arms"])
        targets.update(gripper_targets(frame.get("gripper", "open") == "closed"))
        keyframes.append((float(frame.get("duration", 1.0)), targets))
    last = entry["keyframes"][-1]
    effects = {
        "arm_pose": last["arms"],
        "gripper_closed": last.get("gripper", "open") == "closed",
        "holding_object": bool(entry.get("holds_object", False)),
    }
    return KeyframeMotion(keyframes, groups=("arms", "grippers"), effects=effects)


def _compute(entry, geometry: LegGeometry) -> Motion:
    return Motion(entry.get("duration", 0.2))


def _operator_input(entry, geometry: LegGeometry) -> Motion:
    return OperatorInputMotion(entry.get("duration", 0.3))


_BUILDERS = {
    "posture": _posture,
    "gait": _gait,
    "head_tilt": _head_tilt,
    "arm_sequence": _arm_sequence,
    "compute": _compute,
    "operator_input": _operator_input,
}
