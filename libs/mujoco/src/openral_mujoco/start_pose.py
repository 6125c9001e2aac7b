"""Where a reset leaves a robot: the manifest's keyframe (if any), then its start pose.

``sim.start_pose`` names arm joints and their values in manifest units (the rules of
:mod:`openral_core.rules` keep it to arm joints inside their limits). An arm joint is one
scalar joint whose qpos is its manifest value, so the value is written to the joint's qpos
as it is, over whatever the keyframe put there. :class:`~openral_mujoco.joint_driver.JointDriver`
does this with the addresses it drives (:func:`start_pose_addresses`); code that has only a
model and the manifest (a scene framing its cameras around the start pose) calls
:func:`set_start_pose` after loading the keyframe.
"""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core.models import RobotDescription
from openral_core.tables import HalWiring, joint_name_map

from openral_mujoco.errors import HalError
from openral_mujoco.robot_addresses import IntArray
from openral_mujoco.state import FloatArray


def start_pose_addresses(wiring: HalWiring, qpos: IntArray) -> tuple[IntArray, FloatArray]:
    """(qpos addresses, values) of the wiring's start pose, where ``qpos`` holds each
    manifest joint's qpos address in manifest order."""
    slots = {name: slot for slot, name in enumerate(wiring.joint_names)}
    pose = wiring.start_pose
    addresses = np.array([qpos[slots[name]] for name in pose], dtype=np.intp)
    return addresses, np.array(list(pose.values()), dtype=np.float64)


def set_start_pose(model: mujoco.MjModel, data: mujoco.MjData, robot: RobotDescription) -> None:
    """Write the manifest's start pose (if any) into ``data``, over what the keyframe put
    there: each joint found in ``model`` by its MJCF name (``sim_joint_name`` or its name).

    Raises:
        HalError: A start-pose joint that ``model`` does not have.
    """
    pose = robot.sim.start_pose if robot.sim is not None else None
    mjcf_names = joint_name_map(robot)
    for name, value in (pose or {}).items():
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, mjcf_names[name])
        if joint < 0:
            raise HalError(f"start-pose joint {mjcf_names[name]!r} is not in the model")
        data.qpos[model.jnt_qposadr[joint]] = value
