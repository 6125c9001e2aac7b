"""Self-collision avoidance of the end-effector IK, as one inequality per geom pair.

The manifest lists pairs of body groups (``sim.ik_collision_pairs``: the hand and fingers
against the base and first links, say). Every collision geom (non-zero contype or
conaffinity) of one group is paired with every one of the other, except pairs that touch
by construction or can never collide: the same body or bodies welded together, a parent
and its child, and geoms whose contype and conaffinity never match.

For each pair closer than the margin plus a look-ahead (pairs whose bounding spheres are
farther apart are skipped before MuJoCo measures them), one IK step (the joint displacement
``Δq`` of one control period, the variable of the IK's QP) may close at most a share of what
is left above the margin (``n · (J_b - J_a) Δq >= -gain (d - margin)``, with ``n`` the unit
vector between their nearest points): far pairs cost nothing, a pair at the margin may only
separate. (mink's own ``CollisionAvoidanceLimit`` divides that bound by the period, which
lets a 20 Hz step close twenty times the gap.)

MuJoCo 3.8.1's ``mj_geomDistance`` sometimes reports exactly 0 for two convex meshes
well apart (google-deepmind/mujoco issue 3383), with nearest points (``fromto``) that are
not the nearest (on the Panda: 2.0 cm apart for a link and the hand 0.95 cm apart), or with
none at all. An exact 0 from its native solver is asked again of libccd, the solver it
falls back to with ``mjDSBL_NATIVECCD`` (:meth:`SelfCollisionLimit._distance`): a false
contact neither freezes the arm nor, read as a larger gap, lets it through.
"""

from __future__ import annotations

import itertools

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_mujoco.errors import HalError
from openral_mujoco.state import FloatArray

LOOK_AHEAD_M = 0.09
"""How far beyond the margin a pair starts to constrain the step [m]: more than the hand
travels in one control period at the IK's speed cap (MuJoCo's distance queries grow less
reliable the farther they look)."""
GAIN = 0.85
"""Share of the distance above the margin one step may close."""
_APART_M = 1e-9
"""Nearest points closer than this are one point (a true contact) [m]."""


class SelfCollisionLimit:
    """Geom pairs the IK keeps ``margin_m`` apart (see the module doc)."""

    def __init__(self, model: mujoco.MjModel, pairs: list[tuple[int, int]], margin_m: float):
        self.model, self.pairs, self.margin_m = model, pairs, margin_m
        self.reach_m = margin_m + LOOK_AHEAD_M
        self._a = np.array([a for a, _ in pairs], dtype=np.intp)
        self._b = np.array([b for _, b in pairs], dtype=np.intp)
        self._spheres = model.geom_rbound[self._a] + model.geom_rbound[self._b]
        self._fromto = np.zeros(6)
        self._jac_a, self._jac_b = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        self.clearance_m = self.reach_m
        """The smallest distance [m] of the pairs when :meth:`rows` last looked (at most
        the reach)."""

    def _near(self, data: mujoco.MjData) -> npt.NDArray[np.intp]:
        """The pairs whose bounding spheres are within reach."""
        centres = data.geom_xpos
        apart = np.linalg.norm(centres[self._a] - centres[self._b], axis=1) - self._spheres
        return np.flatnonzero(apart < self.reach_m)

    def clearance(self, data: mujoco.MjData) -> float:
        """The smallest signed distance [m] between the pairs in ``data`` (at most the
        reach)."""
        distances = (self._distance(data, *self.pairs[row]) for row in self._near(data))
        return min(distances, default=self.reach_m)

    def rows(
        self, data: mujoco.MjData, dofs: npt.NDArray[np.intp]
    ) -> tuple[FloatArray, FloatArray]:
        """``G Δq <= h`` over the DOFs ``dofs``: one row per pair in reach, bounding how far
        one step may close it (pairs farther apart add no row)."""
        rows: list[FloatArray] = []
        bounds: list[float] = []
        self.clearance_m = self.reach_m
        for row in self._near(data):
            a, b = self.pairs[row]
            distance = self._distance(data, a, b)
            self.clearance_m = min(self.clearance_m, distance)
            gap = self._fromto[3:] - self._fromto[:3]
            length = float(np.linalg.norm(gap))
            if distance >= self.reach_m or length <= _APART_M:
                continue  # far, or no direction to keep them apart along
            normal = gap / length if distance >= 0.0 else -gap / length
            rows.append(-normal @ self._relative_jacobian(data, a, b)[:, dofs])
            bounds.append(max(GAIN * (distance - self.margin_m), 0.0))
        if not rows:
            return np.zeros((0, len(dofs))), np.zeros(0)
        return np.array(rows), np.array(bounds)

    def _distance(self, data: mujoco.MjData, a: int, b: int) -> float:
        """The pair's signed distance [m] (at most the reach), nearest points in
        ``_fromto``. MuJoCo's native convex solver is asked first; its exact 0 is asked
        again of libccd (MuJoCo's other solver), whose answer is used (see the module doc)."""
        self._fromto[:] = 0.0
        distance = mujoco.mj_geomDistance(self.model, data, a, b, self.reach_m, self._fromto)
        if distance != 0.0:
            return float(distance)
        options = self.model.opt
        native = options.disableflags
        options.disableflags = native | mujoco.mjtDisableBit.mjDSBL_NATIVECCD
        try:
            self._fromto[:] = 0.0
            return float(mujoco.mj_geomDistance(self.model, data, a, b, self.reach_m, self._fromto))
        finally:
            options.disableflags = native

    def _relative_jacobian(self, data: mujoco.MjData, a: int, b: int) -> np.ndarray:
        """How the nearest point of ``b`` moves relative to that of ``a`` per dq [m]."""
        model, fromto = self.model, self._fromto
        mujoco.mj_jac(model, data, self._jac_a, None, fromto[:3], model.geom_bodyid[a])
        mujoco.mj_jac(model, data, self._jac_b, None, fromto[3:], model.geom_bodyid[b])
        return self._jac_b - self._jac_a


def collision_limit(model: mujoco.MjModel, robot: LoadedRobot) -> SelfCollisionLimit | None:
    """The self-collision inequality of the manifest's ``sim.ik_collision_pairs`` (None:
    it lists none, or no pair of their geoms can collide).

    Raises:
        HalError: A listed body is not in the scene's model (the message names the field).
    """
    wiring = robot.tables.hal_wiring
    if wiring is None or not wiring.ik_collision_pairs:
        return None
    pairs: set[tuple[int, int]] = set()
    for index, groups in enumerate(wiring.ik_collision_pairs):
        sides = []
        for field, bodies in zip(("bodies", "avoid"), groups, strict=True):
            where = f"sim.ik_collision_pairs[{index}].{field}"
            sides.append([g for body in bodies for g in _collision_geoms(model, body, where)])
        for a, b in itertools.product(*sides):
            if _can_collide(model, a, b):
                pairs.add((min(a, b), max(a, b)))
    if not pairs:
        return None
    return SelfCollisionLimit(model, sorted(pairs), wiring.ik_collision_margin_m)


def _collision_geoms(model: mujoco.MjModel, body: str, where: str) -> list[int]:
    """The geoms of ``body`` that take part in collisions (non-zero contype or conaffinity)."""
    index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    if index < 0:
        raise HalError(f"{where}: the scene's model has no body {body!r}")
    geoms = np.flatnonzero(model.geom_bodyid == index)
    touching = (model.geom_contype[geoms] != 0) | (model.geom_conaffinity[geoms] != 0)
    return [int(g) for g in geoms[touching]]


def _can_collide(model: mujoco.MjModel, a: int, b: int) -> bool:
    """Not one rigid piece, not parent and child, and their contact bits match."""
    body_a, body_b = model.geom_bodyid[a], model.geom_bodyid[b]
    if model.body_weldid[body_a] == model.body_weldid[body_b]:
        return False
    if body_b == model.body_parentid[body_a] or body_a == model.body_parentid[body_b]:
        return False
    bits = model.geom_contype[a] & model.geom_conaffinity[b]
    return bool(bits or model.geom_contype[b] & model.geom_conaffinity[a])
