"""Where a robot's model puts things: its root body, its reach and its lowest fixed part.

A native scene frames its fixed cameras and places its floor with these.
"""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core.models import RobotDescription
from openral_core.tables import joint_name_map


def lowest_static_point(model: mujoco.MjModel) -> float:
    """Lowest z (at most 0) of the geoms welded to the world in ``model``, e.g. the underside
    of a table that comes with the robot's file."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    lowest = 0.0
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    for geom in np.flatnonzero(model.body_weldid[model.geom_bodyid] == 0):
        if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        center, half = model.geom_aabb[geom, :3], model.geom_aabb[geom, 3:]
        local = center + corners * half
        world = data.geom_xpos[geom] + local @ data.geom_xmat[geom].reshape(3, 3).T
        lowest = min(lowest, float(world[:, 2].min()))
    return lowest


def root_body(model: mujoco.MjModel, robot: RobotDescription) -> int:
    """The robot's root body (the world's child that carries its first manifest joint)."""
    first = next(iter(joint_name_map(robot).values()))
    joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, first)
    return int(model.body_rootid[model.jnt_bodyid[joint]])


def robot_extent(model: mujoco.MjModel, robot: RobotDescription) -> tuple[np.ndarray, float]:
    """Centre and radius (at least 0.2 m) of the robot's links in its start pose, in the
    model's frame; only bodies moved by the manifest's joints and their bases count, so a
    table or a prop in the robot's file does not widen the view. A floating base's
    horizontal offset is removed (the scene puts the base at ``base_pose``)."""
    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_kinematics(model, data)
    joint = mujoco.mjtObj.mjOBJ_JOINT
    mjcf_names = joint_name_map(robot).values()
    bodies = {
        int(model.jnt_bodyid[i])
        for i in range(model.njnt)
        if mujoco.mj_id2name(model, joint, i) in mjcf_names
    }
    bodies |= {int(model.body_parentid[b]) for b in bodies}
    bodies.discard(0)
    points = data.xpos[sorted(bodies)] if bodies else data.xpos[1:]
    if robot.sim is not None and robot.sim.floating_base:
        points = points - data.xpos[root_body(model, robot)] * np.array([1, 1, 0])
    low, high = points.min(axis=0), points.max(axis=0)
    return (low + high) / 2, max(0.2, float(np.linalg.norm(high - low)) / 2)


def robot_bodies(model: mujoco.MjModel, robot: RobotDescription) -> frozenset[int]:
    """Every body of the robot in ``model``: the whole tree under each world child that
    carries a manifest joint (both arms of a bimanual robot; not a table or prop its file
    brings), the bodies its own sensors must not see."""
    roots = set()
    for mjcf_name in joint_name_map(robot).values():
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, mjcf_name)
        if joint >= 0:
            roots.add(int(model.body_rootid[model.jnt_bodyid[joint]]))
    return frozenset(int(b) for b in np.flatnonzero(np.isin(model.body_rootid, list(roots))))
