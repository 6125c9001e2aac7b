"""Small facts read from a compiled MuJoCo model, shared by the HAL, the checker, the
scaffolder and the scene backends (one place for each rule)."""

from __future__ import annotations

import mujoco
import numpy as np

from openral_mujoco.state import FloatArray


def ctrl_limits(model: mujoco.MjModel) -> tuple[FloatArray, FloatArray]:
    """Per-actuator (low, high) control bounds; ±inf where ctrl is unlimited."""
    limited = model.actuator_ctrllimited.astype(bool)
    low: FloatArray = np.where(limited, model.actuator_ctrlrange[:, 0], -np.inf)
    high: FloatArray = np.where(limited, model.actuator_ctrlrange[:, 1], np.inf)
    return low, high


def is_position_servo(model: mujoco.MjModel, actuator: int) -> bool:
    """The actuator's ctrl is a position target (affine bias, as ``<position>`` makes)."""
    return int(model.actuator_biastype[actuator]) == int(mujoco.mjtBias.mjBIAS_AFFINE)


def is_velocity_servo(model: mujoco.MjModel, actuator: int) -> bool:
    """The actuator's ctrl is a velocity target (force = kv·(ctrl - q̇), as ``<velocity>``
    makes: fixed gain kv > 0, affine bias -kv·q̇, no activation dynamics)."""
    kv = float(model.actuator_gainprm[actuator, 0])
    bias = model.actuator_biasprm[actuator]
    return (
        int(model.actuator_dyntype[actuator]) == int(mujoco.mjtDyn.mjDYN_NONE)
        and int(model.actuator_gaintype[actuator]) == int(mujoco.mjtGain.mjGAIN_FIXED)
        and int(model.actuator_biastype[actuator]) == int(mujoco.mjtBias.mjBIAS_AFFINE)
        and kv > 0
        and float(bias[0]) == 0.0
        and float(bias[1]) == 0.0
        and float(bias[2]) == -kv
    )


def is_motor(model: mujoco.MjModel, actuator: int) -> bool:
    """The actuator's ctrl is a force or torque (no bias, as ``<motor>`` makes)."""
    return int(model.actuator_biastype[actuator]) == int(mujoco.mjtBias.mjBIAS_NONE)


def is_scalar_joint(model: mujoco.MjModel, joint: int) -> bool:
    """The joint has one coordinate (hinge or slide), as a manifest joint must."""
    return int(model.jnt_type[joint]) in (
        int(mujoco.mjtJoint.mjJNT_HINGE),
        int(mujoco.mjtJoint.mjJNT_SLIDE),
    )


def root_is_free(model: mujoco.MjModel) -> bool:
    """The model's first joint is a free joint at qpos 0 (a floating base)."""
    return (
        model.njnt > 0
        and int(model.jnt_type[0]) == int(mujoco.mjtJoint.mjJNT_FREE)
        and int(model.jnt_qposadr[0]) == 0
    )


def fixed_tendon_joints(model: mujoco.MjModel, tendon: int) -> tuple[int, ...]:
    """Joints of a fixed tendon in wrap order (no repeats), or () for a spatial tendon."""
    start, count = int(model.tendon_adr[tendon]), int(model.tendon_num[tendon])
    wraps = range(start, start + count)
    if not wraps or any(model.wrap_type[w] != mujoco.mjtWrap.mjWRAP_JOINT for w in wraps):
        return ()
    joints: list[int] = []
    for w in wraps:
        jid = int(model.wrap_objid[w])
        if jid not in joints:
            joints.append(jid)
    return tuple(joints)


def actuator_joints(model: mujoco.MjModel, actuator: int) -> tuple[int, ...]:
    """Joints an actuator moves: its joint, or every joint of its fixed tendon."""
    kind = model.actuator_trntype[actuator]
    target = int(model.actuator_trnid[actuator, 0])
    if kind in (mujoco.mjtTrn.mjTRN_JOINT, mujoco.mjtTrn.mjTRN_JOINTINPARENT):
        return (target,)
    if kind == mujoco.mjtTrn.mjTRN_TENDON:
        return fixed_tendon_joints(model, target)
    return ()
