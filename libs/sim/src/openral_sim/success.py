"""A scene's ``success``: its predicates, checked on the simulation after every control step.

- ``object_above``: the object's centre (its body's world position) is above ``z_m``;
- ``object_in_region``: the centre is inside the box from ``min_m`` to ``max_m``;
- ``gripper_holds``: every finger body of the robot's grippers touches one of the object's
  geoms (a contact in ``data.contact``).

Each must hold without a break for its ``for_s`` (0: at a single step); success is all of
them at once. Only ``data`` is read.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import GripperHolds, ObjectAbove, ObjectInRegion, SuccessPredicate


class SuccessCheck:
    """The ``success`` predicates of one scene on its compiled model."""

    def __init__(
        self,
        predicates: Sequence[SuccessPredicate],
        model: mujoco.MjModel,
        finger_qpos: Sequence[int],
    ) -> None:
        """``finger_qpos``: qpos addresses of the gripper fingers' joints in ``model``."""
        self.predicates = tuple(predicates)
        self._bodies = [
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"scene_{p.object}")
            for p in self.predicates
        ]
        self._fingers = finger_bodies(model, finger_qpos)
        self._geom_body = model.geom_bodyid.copy()
        self._held_s = np.zeros(len(self.predicates))

    @property
    def defined(self) -> bool:
        """True when the scene declares any predicate."""
        return bool(self.predicates)

    def reset(self) -> None:
        """Forget how long each predicate has held."""
        self._held_s[:] = 0.0

    def update(self, data: mujoco.MjData, dt_s: float) -> bool:
        """Account one control step of ``dt_s`` [s]; True when every predicate has held for
        its ``for_s`` (False for a scene without predicates)."""
        if not self.predicates:
            return False
        for index, (predicate, body) in enumerate(zip(self.predicates, self._bodies, strict=True)):
            if self._holds(predicate, body, data):
                self._held_s[index] += dt_s
            else:
                self._held_s[index] = 0.0
        needed = np.array([p.for_s or 0.0 for p in self.predicates])
        holding = self._held_s > 0.0
        return bool(np.all(holding & (self._held_s + 1e-9 >= needed)))

    def _holds(self, predicate: SuccessPredicate, body: int, data: mujoco.MjData) -> bool:
        centre = data.xpos[body]
        if isinstance(predicate, ObjectAbove):
            return bool(centre[2] > predicate.z_m)
        if isinstance(predicate, ObjectInRegion):
            low, high = np.asarray(predicate.min_m), np.asarray(predicate.max_m)
            return bool(np.all((centre >= low) & (centre <= high)))
        assert isinstance(predicate, GripperHolds)
        return fingers_touch(body, data, self._fingers, self._geom_body)


def finger_bodies(model: mujoco.MjModel, finger_qpos: Sequence[int]) -> frozenset[int]:
    """The bodies of the gripper fingers' joints at qpos addresses ``finger_qpos``."""
    by_qpos = {int(model.jnt_qposadr[j]): int(model.jnt_bodyid[j]) for j in range(model.njnt)}
    return frozenset(by_qpos[a] for a in finger_qpos if a in by_qpos)


def fingers_touch(
    body: int, data: mujoco.MjData, fingers: frozenset[int], geom_body: npt.NDArray[np.int32]
) -> bool:
    """True when every finger body touches one of ``body``'s geoms (``gripper_holds``)."""
    if not fingers:
        return False
    touching: set[int] = set()
    count = data.ncon
    pairs = zip(
        data.contact.geom1[:count].tolist(), data.contact.geom2[:count].tolist(), strict=True
    )
    for geom1, geom2 in pairs:
        bodies = {int(geom_body[geom1]), int(geom_body[geom2])}
        if body in bodies:
            touching |= bodies & fingers
    return touching == set(fingers)
