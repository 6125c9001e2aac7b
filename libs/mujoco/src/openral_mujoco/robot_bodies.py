"""Which bodies of a MuJoCo model are the robot's, and which one is its root.

A model may hold more than the robot: a table, props, a second arm its file brings but the
manifest does not name. The robot is every tree under a world child that carries one of its
manifest joints (both arms of a bimanual robot, its mobile base); its root body is the world
child that carries its first manifest joint.
"""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core.models import RobotDescription
from openral_core.tables import joint_name_map


def root_body(model: mujoco.MjModel, robot: RobotDescription) -> int:
    """The robot's root body (the world's child that carries its first manifest joint)."""
    first = next(iter(joint_name_map(robot).values()))
    joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, first)
    return int(model.body_rootid[model.jnt_bodyid[joint]])


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
