"""The robot's kinematic tree as ROS tools see it, read from a MuJoCo model.

One :class:`RobotTree` serves ``/tf``, ``/robot_description`` (the URDF) and
``/joint_states``, so the three can never disagree:

- **links** are the bodies of the robot (:func:`~openral_mujoco.robot_bodies.robot_bodies`),
  named as in the MJCF, under the **base frame** (``FrameNames.base``): the robot's root body
  itself when the base frame has its name, else a frame of its own with the root body as
  its child (at the same pose for a fixed or legged robot; for a mobile base, on the floor
  at the yaw axis, see :class:`~openral_mujoco.mobile_base.DriveGeometry`);
- **joints** are the hinge and slide joints between those bodies, named as the manifest
  names them (``panda_joint1``, not the MJCF's ``joint1``) with the manifest's limits; a
  joint the manifest does not name keeps its MJCF name and range. A joint that follows a
  manifest joint is a **mimic**: one coupled to it by a MuJoCo joint equality (the Panda's
  second finger), or driven by a gripper's mirror actuator (the negated command: ALOHA's
  second finger);
- a mobile base's drive joints and a floating base's free joint are not joints of the tree:
  the base frame itself moves (``odom`` → base frame, or ``world`` → base frame).

Each link's origin is its pose in its parent with every joint at 0 (MuJoCo applies
``qpos - qpos0``; the origin absorbs a joint's ``ref``), and each joint's axis and anchor are
in the child's frame. What a URDF cannot state (a body with two joints, a ball joint, a free
joint below the root, a second root body on a moving base, an unnamed joint) is refused with
:class:`TreeUnsupported` naming the body.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, replace
from enum import StrEnum

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.link_names import LinkNaming
from openral_core.models import LimitedJoint, RobotDescription
from openral_core.tables import RobotTables, joint_name_map

from openral_mujoco.errors import TreeUnsupported
from openral_mujoco.extra_links import check_renames, hang_extra_links
from openral_mujoco.joint_coupling import effort_limit, followers
from openral_mujoco.mobile_base import drive_geometry
from openral_mujoco.robot_addresses import RobotAddresses
from openral_mujoco.robot_bodies import robot_bodies, root_body
from openral_mujoco.state import FloatArray, JointStateSample

IntArray = npt.NDArray[np.intp]
Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]
"""w, x, y, z."""
ORIGIN: Vector = (0.0, 0.0, 0.0)
IDENTITY: Quaternion = (1.0, 0.0, 0.0, 0.0)
UNLIMITED_SLIDE_M = 1000.0
"""Range written for a slide joint the model leaves unlimited [m] (a URDF slide needs one)."""


class BaseKind(StrEnum):
    """How the base frame moves in the world."""

    FIXED = "fixed"
    FLOATING = "floating"
    """On a free joint (a legged robot): ``world`` → base frame moves."""
    MOBILE = "mobile"
    """On a wheeled base: ``odom`` → base frame moves."""


@dataclass(frozen=True)
class Mimic:
    """A joint that follows another: ``value = multiplier * followed + offset``."""

    joint: str
    multiplier: float
    offset: float


@dataclass(frozen=True)
class TreeJoint:
    """A hinge or slide joint between a link and its parent."""

    name: str
    """Its ROS name: the manifest's, else the MJCF's."""
    mjcf_name: str
    kind: str
    """``revolute``, ``continuous`` or ``prismatic`` (URDF joint types)."""
    axis: Vector
    """Unit axis in the child link's frame."""
    anchor: Vector
    """A point of a revolute axis, in the child link's frame [m]."""
    lower: float
    upper: float
    """Position limits [rad or m] (continuous: unused)."""
    velocity: float
    """Velocity limit [rad/s or m/s] (0: unknown)."""
    effort: float
    """Effort limit [N·m or N] (0: unknown)."""
    qpos: int
    dof: int
    """Addresses in the model the tree was read from."""
    manifest: bool
    """True for a joint the manifest names."""
    mimic: Mimic | None = None


@dataclass(frozen=True)
class TreeLink:
    """A frame of the tree: a body of the robot, or the base frame."""

    name: str
    body: int
    """Body id in the tree's model; -1 for a base frame that is no body."""
    parent: str | None
    """The parent link's name; None for the base frame."""
    position: Vector
    quat: Quaternion
    """Pose in the parent with every joint at 0 (the URDF joint origin)."""
    joint: TreeJoint | None
    """The joint that moves it relative to its parent; None: rigidly fixed."""
    fixed_joint: str = ""
    """The name of the fixed joint into it (``frames.joints``; default ``<name>_fixed``)."""


@dataclass(frozen=True)
class RobotTree:
    """The robot's links (parents before children; the base frame first) and joints."""

    base: str
    kind: BaseKind
    root: int
    """The root body's id."""
    links: tuple[TreeLink, ...]

    @property
    def joints(self) -> tuple[TreeJoint, ...]:
        """Every joint of the tree, manifest joints first (in manifest order), then the
        others in body order."""
        joints = [link.joint for link in self.links if link.joint is not None]
        return tuple(sorted(joints, key=lambda j: not j.manifest))

    @functools.cached_property
    def _addresses(self) -> tuple[tuple[str, ...], IntArray, IntArray]:
        joints = self.joints
        qpos = np.array([j.qpos for j in joints], dtype=np.intp)
        return tuple(j.name for j in joints), qpos, np.array([j.dof for j in joints], np.intp)

    def read_joints(self, data: mujoco.MjData) -> JointStateSample:
        """Every joint of the tree as ``data`` holds it, in SI units (positions [rad or m],
        velocities, actuator forces [N·m or N]), in :attr:`joints` order; ``data`` must
        belong to the model the tree was read from."""
        names, qpos, dof = self._addresses
        return JointStateSample(
            names=names,
            positions=data.qpos[qpos].copy(),
            velocities=data.qvel[dof].copy(),
            efforts=data.qfrc_actuator[dof].copy(),
            stamp_ns=time.monotonic_ns(),
            sim_time_s=float(data.time),
        )

    def link(self, name: str) -> TreeLink:
        """The link called ``name``.

        Raises:
            KeyError: No such link.
        """
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)


def robot_tree(
    model: mujoco.MjModel,
    robot: RobotDescription,
    tables: RobotTables,
    addresses: RobotAddresses,
) -> RobotTree:
    """Read the robot's tree from ``model`` (the robot alone, or a scene holding it).

    Args:
        model: A compiled model holding the robot (names as in its own MJCF).
        robot: The manifest.
        tables: Its tables (frame names, mobile base).
        addresses: Where its joints and actuators are in ``model``.

    Raises:
        TreeUnsupported: See the module doc.
    """
    bodies = sorted(robot_bodies(model, robot))
    root = root_body(model, robot)
    kind = _base_kind(model, root, tables)
    zero = _zero_pose_data(model)
    base_pose = _base_pose(model, zero, root, kind, tables)
    naming = tables.frames.naming
    names = {b: naming.link(_body_name(model, b)) for b in bodies}
    base = tables.frames.base
    clash = [b for b in bodies if names[b] == base and b != root]
    if clash:
        raise TreeUnsupported(
            f"the base frame {base!r} is also the name of a body of the robot's model below "
            f"its root body {names[root]!r}; name the base frame otherwise (frames.base, or "
            "mobile_base.base_frame), or after the root body"
        )
    joints = _JointReader(model, robot, addresses, naming)
    links: list[TreeLink] = []
    if names[root] != base:
        links.append(TreeLink(base, -1, None, ORIGIN, IDENTITY, None))
    for body in bodies:
        parent = int(model.body_parentid[body])
        if parent == 0:  # a root body: under the base frame
            if body != root and kind is not BaseKind.FIXED:
                raise TreeUnsupported(
                    f"body {names[body]!r} is a second root of the robot on a moving base"
                )
            if body == root and names[root] == base:
                links.append(
                    TreeLink(base, root, None, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), None)
                )
                continue
            position, quat = _relative(base_pose, _pose(zero, body))
            joint = None if body == root else joints.of(body, names[body])
            links.append(TreeLink(names[body], body, base, position, quat, joint))
            continue
        position, quat = _relative(_pose(zero, parent), _pose(zero, body))
        joint = joints.of(body, names[body])
        links.append(TreeLink(names[body], body, names[parent], position, quat, joint))
    links = [replace(link, fixed_joint=naming.fixed_joint(link.name)) for link in links]
    check_renames(naming, {_body_name(model, b) for b in bodies}, links)
    links = hang_extra_links(joints.with_mimics(links), naming.extra_links)
    return RobotTree(base=base, kind=kind, root=root, links=tuple(links))


# -- base ------------------------------------------------------------------------------------


def _base_kind(model: mujoco.MjModel, root: int, tables: RobotTables) -> BaseKind:
    if tables.mobile_base is not None:
        return BaseKind.MOBILE
    first = int(model.body_jntadr[root])
    if model.body_jntnum[root] == 1 and model.jnt_type[first] == mujoco.mjtJoint.mjJNT_FREE:
        return BaseKind.FLOATING
    if model.body_jntnum[root]:
        raise TreeUnsupported(f"the root body {_body_name(model, root)!r} has joints")
    return BaseKind.FIXED


def _base_pose(
    model: mujoco.MjModel, data: mujoco.MjData, root: int, kind: BaseKind, tables: RobotTables
) -> tuple[FloatArray, FloatArray]:
    """The base frame's world pose with every joint at 0: the root body's, or for a mobile
    base the yaw axis on the base's plane, turned as the root body is."""
    if kind is not BaseKind.MOBILE or tables.mobile_base is None:
        return _pose(data, root)
    geometry = drive_geometry(model, tables.mobile_base)
    yaw_joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, tables.mobile_base.joints[2])
    position, heading = geometry.pose(data.qpos)
    z = float(data.xanchor[yaw_joint, 2])
    quat = np.array([math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)])
    return np.array([position[0], position[1], z]), quat


# -- joints ----------------------------------------------------------------------------------


class _JointReader:
    """Each body's joint as a TreeJoint, and the mimic couplings of the model."""

    def __init__(
        self,
        model: mujoco.MjModel,
        robot: RobotDescription,
        addresses: RobotAddresses,
        naming: LinkNaming,
    ) -> None:
        self.model, self.naming = model, naming
        mjcf_names = joint_name_map(robot)
        self.manifest = {mjcf_names[j.name]: j for j in robot.joints}
        self.followers = followers(model, robot, addresses)

    def of(self, body: int, body_name: str) -> TreeJoint | None:
        """The joint moving ``body`` (None: fixed), or TreeUnsupported."""
        model = self.model
        count = int(model.body_jntnum[body])
        if count == 0:
            return None
        if count > 1:
            raise TreeUnsupported(f"body {body_name!r} has {count} joints; a URDF link has one")
        joint = int(model.body_jntadr[body])
        kind = int(model.jnt_type[joint])
        if kind not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            what = "ball" if kind == mujoco.mjtJoint.mjJNT_BALL else "free"
            raise TreeUnsupported(f"body {body_name!r} has a {what} joint; a URDF has none")
        mjcf = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if not mjcf:
            raise TreeUnsupported(f"the joint of body {body_name!r} has no name in the MJCF")
        return self._joint(joint, mjcf)

    def _joint(self, joint: int, mjcf: str) -> TreeJoint:
        model = self.model
        slide = model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_SLIDE
        declared = self.manifest.get(mjcf)
        lower, upper = (float(v) for v in model.jnt_range[joint])
        if declared is not None and isinstance(declared, LimitedJoint):
            lower, upper = (float(v) for v in declared.position_limits)
        limited = declared is not None and isinstance(declared, LimitedJoint)
        limited = limited or bool(model.jnt_limited[joint])
        if slide and not limited:
            lower, upper, limited = -UNLIMITED_SLIDE_M, UNLIMITED_SLIDE_M, True
        kind = "prismatic" if slide else ("revolute" if limited else "continuous")
        listed = self.naming.limits.get(mjcf) or (0.0, effort_limit(model, joint))
        return TreeJoint(
            name=declared.name if declared is not None else self.naming.joint(mjcf),
            mjcf_name=mjcf,
            kind=kind,
            axis=_vector(model.jnt_axis[joint]),
            anchor=_vector(model.jnt_pos[joint]),
            lower=lower,
            upper=upper,
            velocity=float(declared.velocity_limit) if declared is not None else listed[0],
            effort=float(declared.effort_limit) if declared is not None else listed[1],
            qpos=int(model.jnt_qposadr[joint]),
            dof=int(model.jnt_dofadr[joint]),
            manifest=declared is not None,
        )

    def with_mimics(self, links: list[TreeLink]) -> list[TreeLink]:
        """``links`` with each follower joint's mimic filled in (and the velocity and effort
        limits of the joint it follows)."""
        names = {link.joint.mjcf_name: link.joint for link in links if link.joint is not None}
        out = []
        for link in links:
            joint = link.joint
            coupling = self.followers.get(joint.mjcf_name) if joint is not None else None
            if joint is None or coupling is None or coupling[0] not in names:
                out.append(link)
                continue
            leader = names[coupling[0]]
            mimic = Mimic(leader.name, coupling[1], coupling[2])
            scale = abs(coupling[1])
            followed = TreeJoint(
                **{
                    **joint.__dict__,
                    "mimic": mimic,
                    "velocity": leader.velocity * scale,
                    "effort": leader.effort,
                }
            )
            out.append(TreeLink(**{**link.__dict__, "joint": followed}))
        return out


# -- poses -----------------------------------------------------------------------------------


def _zero_pose_data(model: mujoco.MjModel) -> mujoco.MjData:
    """Kinematics with every hinge and slide joint at 0 (free and ball joints at qpos0)."""
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    for joint in range(model.njnt):
        if model.jnt_type[joint] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            data.qpos[model.jnt_qposadr[joint]] = 0.0
    mujoco.mj_kinematics(model, data)
    return data


def _pose(data: mujoco.MjData, body: int) -> tuple[FloatArray, FloatArray]:
    return np.array(data.xpos[body], dtype=np.float64), np.array(data.xquat[body], np.float64)


def _relative(
    parent: tuple[FloatArray, FloatArray], child: tuple[FloatArray, FloatArray]
) -> tuple[Vector, Quaternion]:
    """``child``'s pose in ``parent``'s frame (both world poses)."""
    inverse = np.empty(4)
    mujoco.mju_negQuat(inverse, parent[1])
    position = np.empty(3)
    mujoco.mju_rotVecQuat(position, child[0] - parent[0], inverse)
    quat = np.empty(4)
    mujoco.mju_mulQuat(quat, inverse, child[1])
    w, x, y, z = (float(v) for v in quat / np.linalg.norm(quat))
    return _vector(position), (w, x, y, z)


def _vector(values: FloatArray) -> Vector:
    x, y, z = (float(v) for v in values)
    return x, y, z


def _body_name(model: mujoco.MjModel, body: int) -> str:
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
    if not name:
        raise TreeUnsupported(f"body {body} of the robot has no name in the MJCF")
    return name
