"""How joint targets become actuator controls in a MuJoCo model.

Shared by :class:`~openral_hal.mujoco_arm.MujocoArmHAL` and the native scene, so the robot
alone and the robot inside a composed scene obey one control law.
"""

from __future__ import annotations

import mujoco
import numpy as np

from openral_mujoco.mjcf_model import is_position_servo, is_scalar_joint
from openral_mujoco.state import FloatArray


def pd_torque(
    kp: FloatArray,
    kd: FloatArray,
    target: FloatArray,
    q: FloatArray,
    qdot: FloatArray,
    low: FloatArray,
    high: FloatArray,
) -> FloatArray:
    """The ``torque_pd`` control law: ``kp * (target - q) - kd * qdot``, clipped to [low, high]."""
    torque: FloatArray = np.minimum(np.maximum(kp * (target - q) - kd * qdot, low), high)
    return torque


def seed_position_servos(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """ctrl ← qpos of the joint for every position-servo actuator on a hinge or slide joint."""
    for actuator in range(model.nu):
        if model.actuator_trntype[actuator] != mujoco.mjtTrn.mjTRN_JOINT:
            continue
        if not is_position_servo(model, actuator):
            continue
        joint = model.actuator_trnid[actuator, 0]
        if not is_scalar_joint(model, joint):
            continue
        low, high = model.actuator_ctrlrange[actuator]
        value = float(data.qpos[model.jnt_qposadr[joint]])
        data.ctrl[actuator] = (
            min(max(value, low), high) if model.actuator_ctrllimited[actuator] else value
        )
