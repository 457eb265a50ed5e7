"""MuJoCo wrapper for the humanoid: loading, position targets, measurements.

This is the only module (besides ``rendering``) that imports MuJoCo; the
discrete semantics in ``atlas_sim.simulator.discrete`` stay importable without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, List, Mapping, Optional, Tuple

import mujoco
import numpy as np

from .kinematics import LegGeometry, POSTURES, JointTargets

MODEL_PATH = Path(__file__).resolve().parent / "models" / "humanoid.xml"

#: Bodies (with their subtrees) that may touch furniture: hands rest on a table to grasp.
#: Any other part of the robot touching furniture is a collision (``obstacle_contacts``).
TOUCHING_BODIES = ("left_hand", "right_hand")


#: Where a geom is sampled for the look-ahead of walks: a 3x3x3 grid over a box, 9 points along
#: a capsule's or cylinder's axis (each a sphere of its radius).
_GRID = np.array([[x, y, z] for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1)], dtype=float)
_AXIS_SAMPLES = np.linspace(-1.0, 1.0, 9)
_LIMB_TYPES = (int(mujoco.mjtGeom.mjGEOM_CAPSULE), int(mujoco.mjtGeom.mjGEOM_CYLINDER))


@dataclass(frozen=True)
class Obstacle:
    """The nearest furniture in a walk's way: its body's name and the free distance to it (m)."""

    body: str
    free_distance: float


@dataclass(frozen=True)
class FallCriteria:
    """The robot counts as fallen when the pelvis drops below ``min_pelvis_height``
    (metres) or the torso leans more than ``max_torso_tilt_deg`` from vertical."""

    min_pelvis_height: float = 0.45
    max_torso_tilt_deg: float = 40.0


class HumanoidPhysics:
    """Owns the MuJoCo model/data of one humanoid and its position targets."""

    def __init__(
        self,
        model_path: Path = MODEL_PATH,
        timestep: Optional[float] = None,
        fall_criteria: FallCriteria = FallCriteria(),
    ) -> None:
        self.model = mujoco.MjModel.from_xml_path(str(model_path))
        if timestep:
            self.model.opt.timestep = timestep
        self.data = mujoco.MjData(self.model)
        self.fall_criteria = fall_criteria
        self.geometry = self._read_leg_geometry()
        self._actuator_ids = {
            mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, i): i
            for i in range(self.model.nu)
        }
        self._joint_qpos = {
            name: self.model.jnt_qposadr[self._joint_id(name)] for name in self._actuator_ids
        }
        self._joint_dof = {
            name: self.model.jnt_dofadr[self._joint_id(name)] for name in self._actuator_ids
        }
        self._pelvis = self._body_id("pelvis")
        self._torso = self._body_id("torso")
        self._mocap = self.model.body_mocapid[self._body_id("pelvis_target")]
        self._object_mocap = self.model.body_mocapid[self._body_id("pickup_object")]
        self._hands = (self._body_id("left_hand"), self._body_id("right_hand"))
        self._weld = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_EQUALITY, "balance_assist")
        robot_bodies = self._subtree(self._pelvis)
        touching = set().union(*(self._subtree(self._body_id(name)) for name in TOUCHING_BODIES))
        geom_body = self.model.geom_bodyid
        #: the robot's geoms that must not touch furniture (all but the hands')
        self._colliding_robot_geoms = {g for g in range(self.model.ngeom)
                                       if geom_body[g] in robot_bodies and geom_body[g] not in touching}
        #: furniture: colliding geoms of the scene on bodies of their own (not the robot, not the floor)
        self._furniture_geoms = {
            g for g in range(self.model.ngeom)
            if geom_body[g] not in robot_bodies and geom_body[g] != 0
            and (self.model.geom_contype[g] or self.model.geom_conaffinity[g])}

    # ----------------------------------------------------------- model lookup
    def _joint_id(self, name: str) -> int:
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)

    def _body_id(self, name: str) -> int:
        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if body < 0:
            raise KeyError(f"model has no body {name!r}")
        return body

    def _subtree(self, root: int) -> set:
        """Ids of ``root`` and every body below it."""
        parents = self.model.body_parentid
        return {b for b in range(self.model.nbody) if b == root or self._descends(b, root, parents)}

    @staticmethod
    def _descends(body: int, root: int, parents) -> bool:
        while body != 0:
            body = parents[body]
            if body == root:
                return True
        return False

    def _body_name(self, body: int) -> str:
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, body)

    def _read_leg_geometry(self) -> LegGeometry:
        """Leg dimensions from the model so IK stays in sync with the MJCF."""
        thigh = self.model.body_pos[self._body_id("left_thigh")]
        shin = self.model.body_pos[self._body_id("left_shin")]
        foot = self.model.body_pos[self._body_id("left_foot")]
        sole = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "left_foot")
        ankle_height = -(self.model.geom_pos[sole][2] - self.model.geom_size[sole][2])
        return LegGeometry(
            thigh_length=float(-shin[2]),
            shin_length=float(-foot[2]),
            hip_offset_y=float(thigh[1]),
            hip_offset_z=float(thigh[2]),
            ankle_height=float(ankle_height),
        )

    @property
    def joint_names(self) -> tuple:
        """Names of the actuated joints (actuators share their joint's name)."""
        return tuple(self._actuator_ids)

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    @property
    def time(self) -> float:
        return float(self.data.time)

    # ------------------------------------------------------------ state setup
    def reset_to_posture(self, posture_name: str, settle_time: float = 0.5) -> None:
        """Place the robot in a named posture with its feet on the floor, let it
        settle under gravity for ``settle_time`` seconds, and restart the clock
        at 0 so every run starts from rest."""
        mujoco.mj_resetData(self.model, self.data)
        posture = POSTURES[posture_name]
        targets = posture.targets(self.geometry)
        for name, angle in targets.items():
            self.data.qpos[self._joint_qpos[name]] = angle
        self.data.qpos[2] = self.geometry.pelvis_height(posture.hip_height)
        self.set_targets(targets)
        self.set_balance_assist(False)
        mujoco.mj_forward(self.model, self.data)
        self.step(round(settle_time / self.timestep))
        self.data.time = 0.0

    # ---------------------------------------------------------------- control
    def set_targets(self, targets: Mapping[str, float]) -> None:
        """Set the position-actuator setpoints of the named joints (radians)."""
        for name, angle in targets.items():
            self.data.ctrl[self._actuator_ids[name]] = angle

    def targets(self, names: Optional[Iterable[str]] = None) -> JointTargets:
        names = self.joint_names if names is None else names
        return {name: float(self.data.ctrl[self._actuator_ids[name]]) for name in names}

    def set_balance_assist(self, active: bool) -> None:
        """Switch the pelvis weld on or off.  When switching on, the target is
        first moved onto the current pelvis pose so the weld does not jerk."""
        if active and not self.balance_assist_active:
            self.move_pelvis_target(self.pelvis_position(), self.data.xquat[self._pelvis])
        self.data.eq_active[self._weld] = 1 if active else 0

    @property
    def balance_assist_active(self) -> bool:
        return bool(self.data.eq_active[self._weld])

    def move_pelvis_target(self, position, quaternion=None) -> None:
        self.data.mocap_pos[self._mocap] = position
        if quaternion is not None:
            self.data.mocap_quat[self._mocap] = quaternion

    def carry_object(self) -> None:
        """Put the object to pick up just below the hands (it is held)."""
        between = (self.data.xpos[self._hands[0]] + self.data.xpos[self._hands[1]]) / 2
        self.data.mocap_pos[self._object_mocap] = between + np.array([0.0, 0.0, -0.12])
        mujoco.mj_kinematics(self.model, self.data)  # so that a frame drawn now shows it there

    def object_position(self) -> np.ndarray:
        return self.data.mocap_pos[self._object_mocap].copy()

    def set_external_force(self, body: str, force) -> None:
        """Apply a constant world-frame force (N) at a body's origin until changed."""
        self.data.xfrc_applied[self._body_id(body), :3] = force

    def step(self, count: int = 1) -> None:
        mujoco.mj_step(self.model, self.data, nstep=count)

    # ----------------------------------------------------------- measurements
    def joint_positions(self, names: Optional[Iterable[str]] = None) -> JointTargets:
        names = self.joint_names if names is None else names
        return {name: float(self.data.qpos[self._joint_qpos[name]]) for name in names}

    def joint_speeds(self, names: Iterable[str]) -> np.ndarray:
        return np.array([self.data.qvel[self._joint_dof[name]] for name in names])

    def pelvis_position(self) -> np.ndarray:
        return self.data.xpos[self._pelvis].copy()

    def pelvis_speed(self) -> float:
        """Linear speed of the floating base (m/s)."""
        return float(np.linalg.norm(self.data.qvel[0:3]))

    def pelvis_yaw(self) -> float:
        """Heading of the pelvis x axis in the floor plane (radians)."""
        axis_x = self.data.xmat[self._pelvis].reshape(3, 3)[:, 0]
        return math.atan2(float(axis_x[1]), float(axis_x[0]))

    def body_position(self, name: str) -> np.ndarray:
        return self.data.xpos[self._body_id(name)].copy()

    def torso_tilt(self) -> float:
        """Angle (radians) between the torso's z axis and the world vertical."""
        torso_z = self.data.xmat[self._torso].reshape(3, 3)[:, 2]
        return math.acos(max(-1.0, min(1.0, float(torso_z[2]))))

    def has_fallen(self) -> bool:
        criteria = self.fall_criteria
        return bool(
            self.pelvis_position()[2] < criteria.min_pelvis_height
            or math.degrees(self.torso_tilt()) > criteria.max_torso_tilt_deg
        )

    # ------------------------------------------------------------- obstacles
    def obstacle_contacts(self) -> List[Tuple[str, str]]:
        """(robot part, furniture body) pairs touching now, robot parts other than the hands.

        The robot must not touch furniture with its body: a leg in a table is a collision
        the physics cannot make right afterwards, so the simulator reports it."""
        pairs = []
        for contact in self.data.contact[: self.data.ncon]:
            geoms = (int(contact.geom1), int(contact.geom2))
            for robot, other in (geoms, geoms[::-1]):
                if robot in self._colliding_robot_geoms and other in self._furniture_geoms:
                    pair = (self._body_name(self.model.geom_bodyid[robot]),
                            self._body_name(self.model.geom_bodyid[other]))
                    if pair not in pairs:
                        pairs.append(pair)
        return pairs

    def _geom_spheres(self, geom: int):
        """Sample spheres (world centres, radii) covering a geom: a limb's axis in 9 spheres of
        its radius (its bounding box would swing far out when the limb tilts), else a grid of
        points over its bounding box."""
        position, frame = self.data.geom_xpos[geom], self.data.geom_xmat[geom].reshape(3, 3)
        if int(self.model.geom_type[geom]) in _LIMB_TYPES:
            radius, half_length = self.model.geom_size[geom, :2]
            centres = position + np.outer(_AXIS_SAMPLES * half_length, frame[:, 2])
            return centres, np.full(len(centres), float(radius))
        center, half = self.model.geom_aabb[geom, :3], self.model.geom_aabb[geom, 3:]
        return position + (center + _GRID * half) @ frame.T, np.zeros(len(_GRID))

    def _walk_frame_spheres(self, geoms, origin, heading):
        """Sample spheres of ``geoms`` as (forward, lateral, height) for a walk from ``origin``
        along ``heading``, and their radii."""
        spheres = [self._geom_spheres(g) for g in geoms]
        points = np.concatenate([centres for centres, _ in spheres])
        left = np.array([-heading[1], heading[0]])
        planar = points[:, :2] - origin
        return (np.stack([planar @ heading, planar @ left, points[:, 2]], axis=1),
                np.concatenate([radii for _, radii in spheres]))

    def obstacle_ahead(self, distance: float, margin: float, turn: float = 0.0, shift: float = 0.0,
                       side_margin: Optional[float] = None) -> Optional[Obstacle]:
        """The furniture a walk of ``distance`` metres would run into.

        The walk goes ``turn`` radians left of the pelvis heading (pi/2: a sidestep to the
        left), starting ``shift`` metres to the left of where the robot stands. Each furniture
        geom is a footprint on the floor in the walk's frame; the robot's parts that must not
        touch furniture, as they stand now, are swept along the walk: those beside it within
        ``side_margin`` (default ``margin``) must stop ``margin`` short of it, whatever their
        height (arms and legs move during and after a walk, so none may end over a table). Returns the
        nearest body in the way and the free distance to it, or None."""
        side_margin = margin if side_margin is None else side_margin
        yaw = self.pelvis_yaw()
        left = np.array([-math.sin(yaw), math.cos(yaw)])
        heading = np.array([math.cos(yaw + turn), math.sin(yaw + turn)])
        origin = self.pelvis_position()[:2]
        robot, radii = self._walk_frame_spheres(sorted(self._colliding_robot_geoms), origin, heading)
        robot[:, :2] += shift * np.array([left @ heading, left @ np.array([-heading[1], heading[0]])])
        nearest: Optional[Obstacle] = None
        for geom in sorted(self._furniture_geoms):
            points, widths = self._walk_frame_spheres([geom], origin, heading)
            low, high = (points - widths[:, None]).min(axis=0), (points + widths[:, None]).max(axis=0)
            facing = ((robot[:, 1] + radii + side_margin > low[1]) & (robot[:, 1] - radii - side_margin < high[1])
                      & (robot[:, 0] - radii < high[0]))
            if not facing.any():
                continue
            free = float(low[0] - (robot[facing, 0] + radii[facing]).max())
            if free < distance + margin and (nearest is None or free < nearest.free_distance):
                nearest = Obstacle(self._body_name(self.model.geom_bodyid[geom]), max(0.0, free))
        return nearest

    def fall_reason(self) -> str:
        height = self.pelvis_position()[2]
        tilt = math.degrees(self.torso_tilt())
        return f"robot fell (pelvis height {height:.2f} m, torso tilt {tilt:.0f} deg)"
