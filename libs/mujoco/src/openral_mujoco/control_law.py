"""How joint targets become actuator controls in a MuJoCo model.

Shared by :class:`~openral_hal.mujoco_arm.MujocoArmHAL` and the native scene, so the robot
alone and the robot inside a composed scene obey one control law.
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt

from openral_mujoco.mjcf_model import is_position_servo, is_scalar_joint
from openral_mujoco.state import FloatArray


def compile_pd_servos(
    model: mujoco.MjModel, actuators: npt.NDArray[np.intp], kp: FloatArray, kd: FloatArray
) -> None:
    """Turn each torque actuator in ``actuators`` into the ``torque_pd`` law inside MuJoCo.

    Afterwards an actuator's ctrl is its joint's set point [rad or m] and MuJoCo computes
    ``kp·(ctrl - q) - kd·dq`` itself at every physics step (no Python per step), clipped to
    what the motor's ctrlrange allowed before (its torque limits, now its forcerange). The
    force is the one the law written in Python gave, scaled by the motor's gain and gear as
    before: ``gain·clip(kp·(ctrl - q) - kd·dq)``.
    """
    for actuator, p, d in zip(actuators.tolist(), kp.tolist(), kd.tolist(), strict=True):
        gain = float(model.actuator_gainprm[actuator, 0])
        gear = float(model.actuator_gear[actuator, 0])
        if model.actuator_ctrllimited[actuator]:
            low, high = sorted(gain * float(v) for v in model.actuator_ctrlrange[actuator])
            if model.actuator_forcelimited[actuator]:  # both clamps held before; both hold
                force_low, force_high = model.actuator_forcerange[actuator].tolist()
                low, high = max(low, force_low), min(high, force_high)
            model.actuator_forcelimited[actuator] = 1
            model.actuator_forcerange[actuator] = (low, high)
        model.actuator_ctrllimited[actuator] = 0
        model.actuator_gaintype[actuator] = mujoco.mjtGain.mjGAIN_FIXED
        model.actuator_gainprm[actuator] = 0.0
        model.actuator_gainprm[actuator, 0] = gain * p
        model.actuator_biastype[actuator] = mujoco.mjtBias.mjBIAS_AFFINE
        model.actuator_biasprm[actuator] = 0.0
        model.actuator_biasprm[actuator, 1] = -gain * p / gear
        model.actuator_biasprm[actuator, 2] = -gain * d / gear


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
