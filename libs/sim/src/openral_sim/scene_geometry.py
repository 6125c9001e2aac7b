"""Where a robot's model puts things: its start pose, the boxes of its geoms and its lowest
fixed part (its root body and bodies: :mod:`openral_mujoco.robot_bodies`).

A native scene frames its fixed cameras and places its floor with these.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import BasePose, RobotDescription
from openral_mujoco.robot_bodies import root_body
from openral_mujoco.start_pose import set_start_pose

BASE_WELD = "scene_base_weld"
"""Name of the equality constraint that holds a welded floating base."""

CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
"""The eight corners of a box of half-size 1."""


def lowest_static_point(model: mujoco.MjModel) -> float:
    """Lowest z (at most 0) of the geoms welded to the world in ``model``, e.g. the underside
    of a table that comes with the robot's file."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    static = np.flatnonzero(model.body_weldid[model.geom_bodyid] == 0)
    static = static[model.geom_type[static] != mujoco.mjtGeom.mjGEOM_PLANE]
    return min(0.0, float(geom_corners(model, data, static)[:, 2].min(initial=0.0)))


def geom_corners(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: Sequence[int] | npt.NDArray[np.int_]
) -> npt.NDArray[np.float64]:
    """World positions of the 8 corners of each geom's bounding box (in the geom's frame,
    ``geom_aabb``) as ``data`` places it: an (8 x len(geoms), 3) array."""
    geoms = np.asarray(geoms, dtype=int)
    local = model.geom_aabb[geoms, None, :3] + CORNERS * model.geom_aabb[geoms, None, 3:]
    rotations = data.geom_xmat[geoms].reshape(-1, 3, 3)
    world: npt.NDArray[np.float64] = data.geom_xpos[geoms, None] + np.einsum(
        "gij,gcj->gci", rotations, local
    )
    return world.reshape(-1, 3)


def start_pose(
    model: mujoco.MjModel, robot: RobotDescription, pose: BasePose | None
) -> mujoco.MjData:
    """A fresh ``MjData`` of a composed scene in the robot's start pose, kinematics done:
    the manifest's keyframe (if any), a floating base's moved to the scene's base pose,
    then ``sim.start_pose`` over it, as a reset puts it before the settle steps."""
    data = mujoco.MjData(model)
    key = robot.sim.keyframe_index if robot.sim is not None else None
    if key is not None:
        mujoco.mj_resetDataKeyframe(model, data, key)
        if robot.sim is not None and robot.sim.floating_base:
            root = root_body(model, robot)
            place_floating_base(data, int(model.jnt_qposadr[model.body_jntadr[root]]), pose)
    set_start_pose(model, data, robot)
    mujoco.mj_kinematics(model, data)
    return data


def place_floating_base(data: mujoco.MjData, free: int, pose: BasePose | None) -> None:
    """Keyframe free-joint poses are world poses: move the free joint whose qpos starts at
    ``free`` to the scene's base ``pose`` (shifted by its position, turned by its yaw)."""
    if pose is None:
        return
    data.qpos[free : free + 3] += np.asarray(pose.position_m or [0.0, 0.0, 0.0])
    quat = np.empty(4)
    yaw = math.radians(pose.yaw_deg or 0.0)
    mujoco.mju_mulQuat(quat, yaw_quat(yaw), data.qpos[free + 3 : free + 7].copy())
    data.qpos[free + 3 : free + 7] = quat


def yaw_quat(yaw: float) -> npt.NDArray[np.float64]:
    """The quaternion (w, x, y, z) of a turn by ``yaw`` [rad] about the world z axis."""
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def hold_base_where_it_is(model: mujoco.MjModel, data: mujoco.MjData, root: int) -> None:
    """Aim the base weld (if any) at body ``root``'s pose now: relpose is the world's pose
    in the root body's frame."""
    weld = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, BASE_WELD)
    if weld < 0:
        return
    mujoco.mj_kinematics(model, data)
    inverse = np.empty(4)
    mujoco.mju_negQuat(inverse, data.xquat[root])
    position = np.empty(3)
    mujoco.mju_rotVecQuat(position, -data.xpos[root], inverse)
    model.eq_data[weld, 0:3] = 0.0
    model.eq_data[weld, 3:6] = position
    model.eq_data[weld, 6:10] = inverse


def object_poses(data: mujoco.MjData, bodies: dict[str, int]) -> dict[str, npt.NDArray[np.float64]]:
    """``<object>_pos`` [m] and ``<object>_quat`` (w, x, y, z) of every scene object, by its
    body id in ``bodies``."""
    state: dict[str, npt.NDArray[np.float64]] = {}
    for name, body in bodies.items():
        state[f"{name}_pos"] = data.xpos[body].copy()
        state[f"{name}_quat"] = data.xquat[body].copy()
    return state
