"""Which joints of a model follow another one: the couplings a URDF states as mimic joints.

A joint the manifest does not name follows a manifest joint when

- a MuJoCo joint equality couples the two affinely (``polycoef`` with only its first two
  terms: the Panda's and OpenArm's second fingers), or
- a gripper's mirror actuator drives it with the negated command (ALOHA's second finger:
  ``value = -leader``).

Also here: the effort limit of a joint the manifest does not name, read from the model.
"""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core.models import RobotDescription
from openral_core.tables import joint_name_map

from openral_mujoco.robot_addresses import RobotAddresses

Coupling = tuple[str, float, float]
"""(MJCF joint followed, multiplier, offset): ``value = multiplier * followed + offset``."""


def followers(
    model: mujoco.MjModel, robot: RobotDescription, addresses: RobotAddresses
) -> dict[str, Coupling]:
    """MJCF joint → (MJCF joint it follows, multiplier, offset) for every joint coupled to a
    manifest joint it is not itself."""
    manifest = set(joint_name_map(robot).values())

    def name(joint: int) -> str:
        return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, int(joint)) or ""

    found: dict[str, Coupling] = {}
    for eq in range(model.neq):
        if model.eq_type[eq] != mujoco.mjtEq.mjEQ_JOINT or not model.eq_active0[eq]:
            continue
        first, second = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])
        c0, c1, *higher = (float(v) for v in model.eq_data[eq, :5])
        if second < 0 or c1 == 0.0 or any(higher):
            continue  # a fixed joint, or not an affine coupling
        q1 = float(model.qpos0[model.jnt_qposadr[first]])
        q2 = float(model.qpos0[model.jnt_qposadr[second]])
        # MuJoCo: q1 - q1_0 = c0 + c1 (q2 - q2_0)
        if name(first) in manifest and name(second) not in manifest:
            found[name(second)] = (name(first), 1.0 / c1, q2 - (q1 + c0) / c1)
        elif name(second) in manifest and name(first) not in manifest:
            found[name(first)] = (name(second), c1, q1 + c0 - c1 * q2)
    for gripper in addresses.grippers:
        mirror = gripper.mirror_actuator
        if mirror is None or model.actuator_trntype[mirror] != mujoco.mjtTrn.mjTRN_JOINT:
            continue
        leader_qpos = int(addresses.qpos[gripper.slot])
        leader = int(np.flatnonzero(model.jnt_qposadr == leader_qpos)[0])
        found[name(model.actuator_trnid[mirror, 0])] = (name(leader), -1.0, 0.0)
    return found


def effort_limit(model: mujoco.MjModel, joint: int) -> float:
    """Effort limit of a joint the manifest does not name: its actuator force range, else
    the force range of an actuator driving it, else 0 (unknown)."""
    if model.jnt_actfrclimited[joint]:
        return float(np.max(np.abs(model.jnt_actfrcrange[joint])))
    for actuator in range(model.nu):
        driven = model.actuator_trntype[actuator] == mujoco.mjtTrn.mjTRN_JOINT
        driven = driven and model.actuator_trnid[actuator, 0] == joint
        if driven and model.actuator_forcelimited[actuator]:
            return float(np.max(np.abs(model.actuator_forcerange[actuator])))
    return 0.0
