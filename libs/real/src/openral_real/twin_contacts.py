"""Would a joint path bring the real arm into the twin scene's fixed geometry?

A path (rows of manifest joint values) is walked in straight joint-space steps of at most
:data:`STEP_RAD` on a scratch copy of the twin's data; at each step the arm's geometry is
placed (``mj_kinematics``) and MuJoCo's collision detection runs (``mj_collision``, which
keeps its contype/conaffinity filters). A contact counts when it is a penetration deeper
than :data:`DEPTH_M` between a geom the arm's joints move and a geom welded to the world
(the table, the pedestal, the robot's own base link), other than the moving link's
parent, and when the pair did not already touch where the path starts (an arm resting on
its pedestal may move away). The first such pair is named in one line.

A gripper's fingers stay where they are measured along the path: a gripper slot's action
is an opening, not a finger position, and fingers that close never reach the table first.
Free objects (a cube) are neither fixed nor checked: pushing one is a task, not a crash.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from itertools import pairwise

import mujoco
import numpy as np
from openral_mujoco.state import FloatArray

STEP_RAD = 0.02
"""Largest joint move between two checked poses [rad or m] (a Panda hand sweeps about
2 cm per step at full reach)."""
DEPTH_M = 1e-3
"""A contact counts from this penetration on [m] (MuJoCo reports touching geoms as
contacts within their margin)."""
MAX_POSES = 20_000
"""Most poses one path is checked at (a path this long is refused as unchecked)."""

Pose = Callable[[mujoco.MjData, FloatArray], None]
"""Writes one row of manifest joint values into a data's joint positions."""


class TwinContacts:
    """Contact screening of joint paths in one model (see the module doc)."""

    def __init__(self, model: mujoco.MjModel, joints: Sequence[int], grippers: Sequence[int]):
        """``joints``: the model's joint of each manifest joint; ``grippers``: the
        manifest slots that are grippers (held at their measured value)."""
        self.model = model
        self._scratch = mujoco.MjData(model)
        self._lock = threading.Lock()
        """One check at a time on the scratch data (an action's and a goal's may overlap)."""
        self._grippers = np.array(grippers, dtype=np.intp)
        moved = {int(model.jnt_bodyid[j]) for j in joints}
        bodies = [b for b in range(model.nbody) if _under(model, b, moved)]
        self._moving = np.isin(model.geom_bodyid, bodies)
        self._fixed = model.body_weldid[model.geom_bodyid] == 0

    def first(
        self, live: mujoco.MjData, start: FloatArray, rows: FloatArray, pose: Pose
    ) -> str | None:
        """The first new arm-against-fixed contact along ``start`` → ``rows`` (one line),
        else None. ``live`` gives everything else's positions (objects stay put)."""
        with self._lock:
            return self._first(live, start, rows, pose)

    def _first(
        self, live: mujoco.MjData, start: FloatArray, rows: FloatArray, pose: Pose
    ) -> str | None:
        data = self._scratch
        data.qpos[:] = live.qpos
        start = np.asarray(start, dtype=np.float64)
        path = np.vstack([start, np.atleast_2d(np.asarray(rows, dtype=np.float64))])
        path[:, self._grippers] = start[self._grippers]
        try:
            points = _densified(path)
        except ValueError as error:
            return str(error)
        already = self._pairs_at(data, start, pose)
        for point in points:
            touching = self._pairs_at(data, point, pose)
            new = [pair for pair in touching if pair not in already]
            if new:
                return self._said(new[0], point)
        return None

    def _pairs_at(
        self, data: mujoco.MjData, point: FloatArray, pose: Pose
    ) -> list[tuple[int, int]]:
        """(arm geom, fixed geom) pairs in contact with the arm at ``point``."""
        pose(data, point)
        mujoco.mj_kinematics(self.model, data)
        mujoco.mj_collision(self.model, data)
        pairs = []
        contacts = data.contact
        for index in range(data.ncon):
            if contacts.dist[index] > -DEPTH_M:
                continue
            pair = self._arm_against_fixed(int(contacts.geom1[index]), int(contacts.geom2[index]))
            if pair is not None:
                pairs.append(pair)
        return pairs

    def _arm_against_fixed(self, one: int, other: int) -> tuple[int, int] | None:
        for arm, fixed in ((one, other), (other, one)):
            if self._moving[arm] and self._fixed[fixed] and not self._parent(arm, fixed):
                return arm, fixed
        return None

    def _parent(self, arm: int, fixed: int) -> bool:
        """True when ``fixed`` is on the body the arm geom's link hangs from."""
        model = self.model
        link = int(model.body_weldid[model.geom_bodyid[arm]])
        return int(model.body_parentid[link]) == int(model.geom_bodyid[fixed])

    def _said(self, pair: tuple[int, int], point: FloatArray) -> str:
        joints = ", ".join(f"{value:.3f}" for value in point)
        return (
            f"the path would bring {_geom_name(self.model, pair[0])} into "
            f"{_geom_name(self.model, pair[1])} (the twin scene's fixed geometry) at joints "
            f"[{joints}]"
        )


def _densified(path: FloatArray) -> list[FloatArray]:
    """The path's points, with straight steps of at most :data:`STEP_RAD` between them.

    Raises:
        ValueError: More than :data:`MAX_POSES` poses.
    """
    points: list[FloatArray] = []
    for begin, end in pairwise(path):
        steps = max(1, int(np.ceil(np.max(np.abs(end - begin)) / STEP_RAD)))
        if len(points) + steps > MAX_POSES:
            raise ValueError(f"the path needs over {MAX_POSES} poses to check; shorten it")
        points.extend(begin + (end - begin) * (k / steps) for k in range(1, steps + 1))
    return points


def _under(model: mujoco.MjModel, body: int, roots: set[int]) -> bool:
    """True when ``body`` is one of ``roots`` or hangs below one."""
    while body > 0:
        if body in roots:
            return True
        body = int(model.body_parentid[body])
    return False


def _geom_name(model: mujoco.MjModel, geom: int) -> str:
    """``body`` (its geom's name too when it has one)."""
    body = model.body(int(model.geom_bodyid[geom])).name or f"body {model.geom_bodyid[geom]}"
    name = model.geom(geom).name
    return f"{body} ({name})" if name else body
