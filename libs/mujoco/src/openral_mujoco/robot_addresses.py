"""Where one robot's joints, fingers and actuators live in a MuJoCo model.

The manifest's wiring (``HalWiring``) gives addresses in the robot's *own* model. Composed
into a scene (props with free joints before it, a prefix, other robots), the same joints sit
at other addresses: :func:`locate_robot` finds each of them again by name — a joint by its
name, an actuator by its name or, when it has none, by the joint or tendon it drives — so
one driver serves the robot alone and the robot inside any scene.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.tables import GripperWiring, HalWiring

from openral_mujoco.errors import HalError

IntArray = npt.NDArray[np.intp]
AnyIntArray = npt.NDArray[np.integer]
"""An index array as MuJoCo hands it out (int32 addresses)."""


@dataclass(frozen=True)
class LocatedGripper:
    """One gripper's fingers and actuators in a model; ``slot`` is its manifest joint index."""

    slot: int
    wiring: GripperWiring
    finger_qpos: IntArray
    finger_qvel: IntArray
    actuator: int
    mirror_actuator: int | None


@dataclass(frozen=True)
class RobotAddresses:
    """Per manifest joint (in manifest order): qpos, qvel and actuator index in one model."""

    qpos: IntArray
    qvel: IntArray
    actuator: IntArray
    grippers: tuple[LocatedGripper, ...]

    @property
    def arm_slots(self) -> IntArray:
        """Manifest joint indices that are not grippers (driven as joint positions)."""
        grippers = {g.slot for g in self.grippers}
        return np.array([i for i in range(len(self.qpos)) if i not in grippers], dtype=np.intp)


def locate_robot(wiring: HalWiring, own: mujoco.MjModel, model: mujoco.MjModel) -> RobotAddresses:
    """The wiring's addresses, taken in ``own`` (the robot's model), found in ``model``.

    ``own`` and ``model`` may be the same model (the robot alone): then nothing moves.

    Raises:
        HalError: An address outside ``own``, or a joint or actuator ``model`` does not
            have (or has twice); one line naming them.
    """
    joints, actuators = _JointMap(own, model), _ActuatorMap(own, model)
    names = wiring.joint_names
    grippers = tuple(
        LocatedGripper(
            slot=names.index(g.joint),
            wiring=g,
            finger_qpos=np.array([joints.qpos(a) for a in g.qpos_addrs], dtype=np.intp),
            finger_qvel=np.array([_dof_of(own, model, joints, a) for a in g.qpos_addrs], np.intp),
            actuator=actuators.index(g.actuator_index),
            mirror_actuator=None
            if g.mirror_actuator_index is None
            else actuators.index(g.mirror_actuator_index),
        )
        for g in wiring.grippers
    )
    return RobotAddresses(
        qpos=np.array([joints.qpos(wiring.joint_qpos_addr[n]) for n in names], dtype=np.intp),
        qvel=np.array([joints.qvel(wiring.joint_qvel_addr[n]) for n in names], dtype=np.intp),
        actuator=np.array([actuators.index(wiring.actuator_index[n]) for n in names], np.intp),
        grippers=grippers,
    )


def _dof_of(own: mujoco.MjModel, model: mujoco.MjModel, joints: _JointMap, qpos: int) -> int:
    """The qvel address (in ``model``) of the one-value joint at ``qpos`` of ``own``."""
    joint = int(np.flatnonzero(own.jnt_qposadr <= qpos)[-1])
    return joints.qvel(int(own.jnt_dofadr[joint]))


class _JointMap:
    """qpos/qvel addresses of ``own`` → the same joint's addresses in ``model``."""

    def __init__(self, own: mujoco.MjModel, model: mujoco.MjModel) -> None:
        self.own, self.model, self.same = own, model, own is model

    def qpos(self, address: int) -> int:
        return self._move(address, self.own.nq, self.own.jnt_qposadr, self.model.jnt_qposadr)

    def qvel(self, address: int) -> int:
        return self._move(address, self.own.nv, self.own.jnt_dofadr, self.model.jnt_dofadr)

    def _move(
        self,
        address: int,
        size: int,
        own_adr: npt.NDArray[np.integer],
        adr: npt.NDArray[np.integer],
    ) -> int:
        if not 0 <= address < size:
            raise HalError(f"address {address} is outside the robot's model (0..{size - 1})")
        if self.same:
            return address
        joint = int(np.flatnonzero(own_adr <= address)[-1])  # addresses ascend by joint
        name = mujoco.mj_id2name(self.own, mujoco.mjtObj.mjOBJ_JOINT, joint)
        found = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name) if name else -1
        if found < 0:
            what = f"joint {name!r}" if name else f"the unnamed joint {joint}"
            raise HalError(f"{what} of the robot's model is not in the scene's model")
        return int(adr[found]) + address - int(own_adr[joint])


class _ActuatorMap:
    """Actuator indices of ``own`` → the same actuator in ``model``."""

    def __init__(self, own: mujoco.MjModel, model: mujoco.MjModel) -> None:
        self.own, self.same = own, own is model
        if not self.same:
            keys = [_actuator_key(model, i) for i in range(model.nu)]
            self.lookup = {k: i for i, k in enumerate(keys) if keys.count(k) == 1}

    def index(self, actuator: int) -> int:
        if not 0 <= actuator < self.own.nu:
            raise HalError(
                f"actuator {actuator} is outside the robot's model (0..{self.own.nu - 1})"
            )
        if self.same:
            return actuator
        key = _actuator_key(self.own, actuator)
        if key not in self.lookup:
            raise HalError(f"actuator {key} of the robot's model is not once in the scene's model")
        return self.lookup[key]


_TARGETS: dict[int, Callable[[mujoco.MjModel, int], str | None]] = {
    int(mujoco.mjtTrn.mjTRN_JOINT): lambda m, i: mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, i),
    int(mujoco.mjtTrn.mjTRN_TENDON): lambda m, i: mujoco.mj_id2name(
        m, mujoco.mjtObj.mjOBJ_TENDON, i
    ),
}


def _actuator_key(model: mujoco.MjModel, actuator: int) -> str:
    """An actuator's name, else ``'driving <joint|tendon name>'`` (what identifies it)."""
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator)
    if name:
        return repr(name)
    target = _TARGETS.get(int(model.actuator_trntype[actuator]))
    driven = target(model, int(model.actuator_trnid[actuator, 0])) if target else None
    return f"driving {driven!r}" if driven else f"#{actuator} (unnamed)"
