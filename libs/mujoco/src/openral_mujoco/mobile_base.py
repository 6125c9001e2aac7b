"""A robot's wheeled base in MuJoCo: its model file, its compiled model and the geometry of
its holonomic drive.

The base is a model of its own (``mobile_base.mjcf_uri``), found and confined like the
robot's (:mod:`openral_mujoco.mjcf_uri`); a native scene attaches the robot's model to the
base's ``mount_body`` (``openral_sim.scene_base``). A holonomic base moves on three joints of
its root body: slides ``x`` and ``y`` followed by a hinge ``yaw`` about the vertical. Because
the slides come first, they move along the axes of the frame the base is placed in, and the
hinge's axis (the base frame's origin, see :class:`DriveGeometry`) moves exactly with them:
its world velocity is the slides' velocities along their axes. ``openral robot check``
verifies that layout (:func:`openral_mujoco.model_check.check_robot`) before anything relies
on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.errors import ManifestError
from openral_core.located import error_at
from openral_core.models import RobotDescription
from openral_core.tables import MobileBaseWiring

from openral_mujoco.mjcf_uri import resolve_manifest_uri
from openral_mujoco.model_cache import cached_mjcf

IntArray = npt.NDArray[np.intp]
FloatArray = npt.NDArray[np.float64]


def base_model_file(robot: RobotDescription, manifest_dir: Path | None = None) -> Path:
    """The checked MJCF file of ``robot``'s ``mobile_base.mjcf_uri``.

    Args:
        robot: A manifest with a ``mobile_base``.
        manifest_dir: Its folder; defaults to the folder it was loaded from, else
            ``robots/<name>/``.

    Raises:
        ManifestError: At ``mobile_base.mjcf_uri`` (or at ``base`` without a mobile base).
    """
    if robot.mobile_base is None:
        raise error_at(robot, ("base",), "the robot has no mobile_base; it has no base model")
    field = ("mobile_base", "mjcf_uri")
    return resolve_manifest_uri(robot, robot.mobile_base.mjcf_uri, field, manifest_dir)


def compile_base_model(robot: RobotDescription, path: Path) -> mujoco.MjModel:
    """The base's model at ``path`` alone, compiled (or from the model cache).

    Raises:
        ManifestError: At ``mobile_base.mjcf_uri`` when MuJoCo cannot load the file.
    """

    return cached_base_model(robot, path)[0]


def cached_base_model(robot: RobotDescription, path: Path) -> tuple[mujoco.MjModel, str | None]:
    """:func:`compile_base_model` and the fingerprint of the files it read (None: none)."""
    return cached_mjcf(path, "base", lambda error: unloadable_base(robot, path, error))


def base_spec(robot: RobotDescription, path: Path) -> mujoco.MjSpec:
    """The base's model at ``path`` as a spec to attach.

    Raises:
        ManifestError: At ``mobile_base.mjcf_uri`` when MuJoCo cannot read the file.
    """
    try:
        return mujoco.MjSpec.from_file(str(path))
    except ValueError as error:
        raise unloadable_base(robot, path, error) from None


def unloadable_base(robot: RobotDescription, path: Path, error: Exception) -> ManifestError:
    """The located error for a base MJCF file MuJoCo refuses (one line of its message)."""
    text = str(error).strip()
    first_line = text.splitlines()[0] if text else type(error).__name__
    message = f"{path} does not load in MuJoCo: {first_line}"
    return error_at(robot, ("mobile_base", "mjcf_uri"), message)


@dataclass(frozen=True)
class DriveGeometry:
    """Where a holonomic base's joints and actuators are in a model, and its planar frame.

    All positions and directions are in the world frame of ``model`` at qpos0, where the
    slides' axes stay (their body's parent is the world). The base frame's origin is the
    yaw hinge's axis on the base's plane; its heading is the root body's.
    """

    qpos: IntArray
    """qpos addresses of x, y, yaw."""
    dof: IntArray
    """qvel addresses of x, y, yaw."""
    actuator: IntArray
    """Actuators driving x, y, yaw."""
    kv: FloatArray
    """Velocity gain of each actuator [N·s/m, N·m·s/rad]."""
    friction: FloatArray
    """Dry friction (frictionloss) of each joint [N, N·m]."""
    ctrl_low: FloatArray
    ctrl_high: FloatArray
    slides: FloatArray
    """2 x 2: the x and y slides' horizontal directions as columns [unitless]."""
    to_slides: FloatArray
    """Inverse of ``slides``: a horizontal world velocity → slide velocities."""
    yaw_sign: float
    """+1 when the hinge turns counter-clockwise seen from above for a positive qpos, else -1."""
    anchor: FloatArray
    """The hinge's axis (x, y) at qpos0 [m]."""
    heading: float
    """The root body's heading at qpos0 [rad]."""
    root_offset: FloatArray
    """The root body's origin in the base frame (x, y, z) [m]: fixed, since both turn with
    the base (the Omron's body ``base`` is 0.21 m ahead of its yaw axis)."""

    def pose(self, qpos: FloatArray) -> tuple[FloatArray, float]:
        """The base frame's world (x, y) [m] and heading [rad] at ``qpos``."""
        q = qpos[self.qpos]
        position: FloatArray = self.anchor + self.slides @ q[:2]
        return position, self.heading + self.yaw_sign * float(q[2])

    def world_twist(self, qvel: FloatArray) -> tuple[FloatArray, float]:
        """The base frame's world velocity (vx, vy) [m/s] and turn rate [rad/s]."""
        v = qvel[self.dof]
        velocity: FloatArray = self.slides @ v[:2]
        return velocity, self.yaw_sign * float(v[2])


def drive_geometry(model: mujoco.MjModel, wiring: MobileBaseWiring) -> DriveGeometry:
    """The drive of ``wiring`` in ``model`` (the base alone or a scene holding it), whose
    joints and actuators were checked to form a holonomic drive.

    Raises:
        KeyError: A joint or actuator of ``wiring`` is not in ``model``.
    """
    joints = [_id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in wiring.joints]
    actuators = [_id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name) for name in wiring.actuators]
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    axes = data.xaxis[joints]
    root = int(model.jnt_bodyid[joints[2]])
    rotation = data.xmat[root].reshape(3, 3)
    slides = np.array(axes[:2, :2].T, dtype=np.float64)
    limited = model.actuator_ctrllimited[actuators].astype(bool)
    ranges = model.actuator_ctrlrange[actuators]
    return DriveGeometry(
        qpos=np.array(model.jnt_qposadr[joints], dtype=np.intp),
        dof=np.array(model.jnt_dofadr[joints], dtype=np.intp),
        actuator=np.array(actuators, dtype=np.intp),
        kv=np.array(model.actuator_gainprm[actuators, 0], dtype=np.float64),
        friction=np.array(model.dof_frictionloss[model.jnt_dofadr[joints]], dtype=np.float64),
        ctrl_low=np.where(limited, ranges[:, 0], -np.inf),
        ctrl_high=np.where(limited, ranges[:, 1], np.inf),
        slides=slides,
        to_slides=np.asarray(np.linalg.inv(slides), dtype=np.float64),
        yaw_sign=1.0 if axes[2, 2] > 0 else -1.0,
        anchor=np.array(data.xanchor[joints[2], :2], dtype=np.float64),
        heading=math.atan2(rotation[1, 0], rotation[0, 0]),
        root_offset=np.asarray(
            rotation.T @ (data.xpos[root] - data.xanchor[joints[2]]), np.float64
        ),
    )


def drive_problems(model: mujoco.MjModel, wiring: MobileBaseWiring) -> list[tuple[str, str]]:
    """What keeps ``wiring``'s joints and actuators in ``model`` from being a holonomic
    drive, as (field path, what the model has); empty when they are one."""
    joint = mujoco.mjtObj.mjOBJ_JOINT
    ids = [mujoco.mj_name2id(model, joint, name) for name in wiring.joints]
    problems = []
    kinds = (mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_HINGE)
    for axis, jid, kind in zip(("x", "y", "yaw"), ids, kinds, strict=True):
        if jid < 0:
            problems.append((f"mobile_base.joints.{axis}", "no such joint"))
        elif int(model.jnt_type[jid]) != int(kind):
            found = mujoco.mjtJoint(int(model.jnt_type[jid])).name.removeprefix("mjJNT_")
            problems.append((f"mobile_base.joints.{axis}", f"a {found.lower()} there"))
    if problems:
        return problems
    bodies = {int(model.jnt_bodyid[j]) for j in ids}
    root = int(model.jnt_bodyid[ids[2]])
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    axes = data.xaxis[ids]
    if len(bodies) != 1 or int(model.body_parentid[root]) != 0:
        problems.append(("mobile_base.joints", "not all on one child body of the world"))
    elif not (ids[0] < ids[2] and ids[1] < ids[2]):
        problems.append(("mobile_base.joints.yaw", "the hinge before a slide"))
    elif abs(axes[2, 2]) < 0.999 or max(abs(axes[0, 2]), abs(axes[1, 2])) > 1e-3:
        problems.append(("mobile_base.joints", "a tilted hinge or slide"))
    elif abs(np.linalg.det(axes[:2, :2])) < 0.5:
        problems.append(("mobile_base.joints", "slides x and y far from perpendicular"))
    return problems


def mount_problem(model: mujoco.MjModel, wiring: MobileBaseWiring) -> str | None:
    """Why ``wiring.mount_body`` cannot carry the robot in the base's ``model`` (it must be
    a body the base's drive moves), or None."""
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, wiring.mount_body)
    if body < 0:
        return "not in the model"
    yaw = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, wiring.joints[2])
    if body == 0 or (
        yaw >= 0 and model.body_rootid[body] != model.body_rootid[model.jnt_bodyid[yaw]]
    ):
        return "a body the base does not carry"
    return None  # (a missing yaw joint is its own finding)


def _id(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    index = mujoco.mj_name2id(model, kind, name)
    if index < 0:
        raise KeyError(f"{name!r} is not in the model")
    return int(index)
