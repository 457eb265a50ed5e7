"""Joint-space postures and leg inverse kinematics for the atlas_sim humanoid.

Pure numpy: nothing here touches MuJoCo, so postures can be unit-tested and
reused by any motion generator.  Joint names and sign conventions are those of
``models/humanoid.xml`` (positive pitch swings a limb backwards, positive knee
angle bends the knee, positive neck pitch looks down).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, Mapping

JointTargets = Dict[str, float]

SIDES = ("left", "right")
LEG_JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
ARM_JOINTS = ("shoulder_pitch", "shoulder_roll", "elbow", "wrist")

#: Joint groups a motion can claim.  Two motions that claim a common group
#: cannot run at the same time (see ``atlas_sim.simulator.atlas_simulator``).
JOINT_GROUPS: Dict[str, tuple] = {
    "legs": tuple(f"{side}_{joint}" for side in SIDES for joint in LEG_JOINTS),
    "torso": ("back_pitch",),
    "head": ("neck_pitch",),
    "arms": tuple(f"{side}_{joint}" for side in SIDES for joint in ARM_JOINTS),
    "grippers": tuple(f"{side}_grip" for side in SIDES),
}

#: Named hip heights (hip joint above the floor, metres) of the leg postures.
HIP_HEIGHTS = {"crouch": 0.62, "stand": 0.80, "walk": 0.78}

GRIPPER_OPEN = 0.0
GRIPPER_CLOSED = -1.0

#: Arm postures, applied symmetrically (shoulder roll is mirrored on the right).
ARM_POSES: Dict[str, Mapping[str, float]] = {
    # Hanging at the sides, elbows slightly bent.
    "sides": {"shoulder_pitch": 0.0, "shoulder_roll": 0.15, "elbow": -0.3, "wrist": 0.0},
    # Tucked for the stand_prep crouch.
    "tucked": {"shoulder_pitch": -0.3, "shoulder_roll": 0.2, "elbow": -1.2, "wrist": 0.0},
    # Manipulation ready pose: forearms pointing forward.
    "forward": {"shoulder_pitch": -0.5, "shoulder_roll": 0.15, "elbow": -1.1, "wrist": 0.0},
    # Pre-grasp: hands raised in front of the chest.
    "pregrasp": {"shoulder_pitch": -0.9, "shoulder_roll": 0.1, "elbow": -1.0, "wrist": 0.2},
    # Reaching forward and down to an object.
    "reach": {"shoulder_pitch": -0.8, "shoulder_roll": 0.05, "elbow": -0.5, "wrist": 0.3},
    # Holding a picked-up object close to the chest.
    "lifted": {"shoulder_pitch": -0.7, "shoulder_roll": 0.1, "elbow": -1.1, "wrist": -0.2},
}


@dataclass(frozen=True)
class LegGeometry:
    """Leg dimensions used by the inverse kinematics (metres).

    ``hip_offset_y``/``hip_offset_z`` locate the hip joints in the pelvis frame,
    ``ankle_height`` is the height of the ankle joint above the foot sole.
    The defaults match ``models/humanoid.xml``; ``atlas_sim.simulator.physics`` re-reads
    them from the loaded model.
    """

    thigh_length: float = 0.4
    shin_length: float = 0.4
    hip_offset_y: float = 0.1
    hip_offset_z: float = -0.06
    ankle_height: float = 0.05

    @property
    def max_reach(self) -> float:
        return self.thigh_length + self.shin_length

    def pelvis_height(self, hip_height: float) -> float:
        """Pelvis origin height for a given hip joint height."""
        return hip_height - self.hip_offset_z


def sagittal_leg_ik(geometry: LegGeometry, forward: float, down: float) -> tuple:
    """Hip pitch, knee and ankle pitch that put the ankle at (forward, -down) from the hip.

    Planar two-link IK in the sagittal plane with the knee bending backwards;
    the ankle pitch keeps the sole parallel to the pelvis.  Targets beyond reach
    are pulled in to 99.9 % of the leg length rather than raising, because a
    slightly-short leg is harmless for a position-controlled robot.
    """
    upper, lower = geometry.thigh_length, geometry.shin_length
    distance = math.hypot(forward, down)
    distance = min(distance, 0.999 * (upper + lower))
    cos_knee = (distance**2 - upper**2 - lower**2) / (2 * upper * lower)
    knee = math.acos(max(-1.0, min(1.0, cos_knee)))
    # Angle of the thigh from the downward vertical, positive = forwards.
    thigh_forward = math.atan2(forward, down) + math.atan2(
        lower * math.sin(knee), upper + lower * math.cos(knee)
    )
    hip_pitch = -thigh_forward
    ankle_pitch = -(hip_pitch + knee)
    return hip_pitch, knee, ankle_pitch


def leg_targets(
    geometry: LegGeometry, side: str, forward: float, down: float
) -> JointTargets:
    """Joint targets of one leg whose ankle sits ``forward``/``down`` of its hip."""
    hip_pitch, knee, ankle_pitch = sagittal_leg_ik(geometry, forward, down)
    return {
        f"{side}_hip_yaw": 0.0,
        f"{side}_hip_roll": 0.0,
        f"{side}_hip_pitch": hip_pitch,
        f"{side}_knee": knee,
        f"{side}_ankle_pitch": ankle_pitch,
        f"{side}_ankle_roll": 0.0,
    }


def standing_legs(geometry: LegGeometry, hip_height: float) -> JointTargets:
    """Both legs straight below the hips with the given hip height."""
    down = hip_height - geometry.ankle_height
    targets: JointTargets = {}
    for side in SIDES:
        targets.update(leg_targets(geometry, side, 0.0, down))
    return targets


def arm_targets(pose_name: str) -> JointTargets:
    """Joint targets of both arms for a named entry of ``ARM_POSES``."""
    pose = ARM_POSES[pose_name]
    targets: JointTargets = {}
    for side in SIDES:
        mirror = 1.0 if side == "left" else -1.0
        for joint, angle in pose.items():
            value = mirror * angle if joint == "shoulder_roll" else angle
            targets[f"{side}_{joint}"] = value
    return targets


def gripper_targets(closed: bool) -> JointTargets:
    value = GRIPPER_CLOSED if closed else GRIPPER_OPEN
    return {f"{side}_grip": value for side in SIDES}


@dataclass(frozen=True)
class Posture:
    """A whole-body posture: leg height, torso lean and arm pose."""

    hip_height: float
    arm_pose: str
    back_pitch: float = 0.0

    def targets(self, geometry: LegGeometry) -> JointTargets:
        targets = standing_legs(geometry, self.hip_height)
        targets.update(arm_targets(self.arm_pose))
        targets["back_pitch"] = self.back_pitch
        return targets


#: Postures that control modes can name in the ``simulation:`` config section.
POSTURES: Dict[str, Posture] = {
    "crouch": Posture(hip_height=HIP_HEIGHTS["crouch"], arm_pose="tucked", back_pitch=0.15),
    "stand": Posture(hip_height=HIP_HEIGHTS["stand"], arm_pose="sides"),
    "manipulate": Posture(hip_height=HIP_HEIGHTS["stand"], arm_pose="forward"),
}
