"""Planar lidar scans of a native scene, ray-cast with MuJoCo's ``mj_multiRay``.

A manifest :class:`~openral_core.models.LidarSensor` casts ``width`` rays from its MJCF
``site``, in the site's x-y plane, at angles evenly spaced from the first to the last of
``angle_range_deg`` (both included; one ray: the first angle), counter-clockwise about the
site's z axis, 0 along the site's x axis. A ray reads the distance to the first surface it
meets [m]; REP 117: ``+inf`` when nothing is hit within ``range_m``'s maximum, ``-inf`` when
the hit is closer than its minimum. A range of [-180, 180] deg closes the circle, so its
first and last rays coincide.

What a lidar sees is what MuJoCo's ray casting sees with ``flg_static=1`` (static geoms of
the world included) and the renderer's default geom groups, :data:`VISIBLE_GROUPS` (0, 1
and 2: what a camera and the depth sensors show; menagerie models keep their collision-only
geoms in group 3, unseen). Like the renderer, it never sees a geom whose colour (or
material) has alpha 0. It never sees the robot either: every geom on ``excluded_bodies``.

How the robot is left out, and why a private copy of the model: ``mj_multiRay`` can leave
out one body (``bodyexclude``) or whole geom groups, and a robot has many bodies sharing
groups with the world. The scanner therefore keeps its own copy of the model in which the
excluded geoms are moved to group :data:`HIDDEN_GROUP`, which :data:`VISIBLE_GROUPS` leaves
out: one native call per scan, exact even when the site sits inside the robot's own mesh
(recasting past each robot hit would cost a Python-level ``mj_ray`` per ray and hit, and
mis-read a world surface that starts inside the robot). The copy also switches off
``mj_multiRay``'s per-body culling (``body_bvhadr = -1``): in MuJoCo 3.8 that culling puts a
body's bounding sphere at an offset it does not rotate with the body, and builds it from
collision geoms only, so it misses hits ``mj_ray`` finds (5 of 360 rays cast around the G1's
torso at a random pose). With it off every ray tests every seen geom, as ``mj_ray`` does;
the cost is small next to the robot's meshes, which the copy no longer tests at all. Ray
casting does not depend on the copy's dynamics, so the scene's own data is used with it
as is.

The copy is the price: as much memory as the model (76 MB for the G1 tabletop, about 40 ms
to make), taken once. Fields of the model changed after the scanner is built (geom sizes,
colours, groups) are not seen by it; build a new scanner after changing them.

Cost (measured on this 2-core machine): in the G1 tabletop scene (74 geoms, robot
excluded) a 180-ray scan takes 0.025 ms and a 1024-ray scan 0.10 ms (casting against the
robot's own meshes instead, as a scan without the exclusion does, 2.4 ms and 12 ms); in
the small scene of ``tests/sim/test_lidar_scan.py`` 0.012 ms and 0.036 ms (``-s`` prints
them).

A ``sensor_msgs/LaserScan`` takes :attr:`LidarScanner.angle_min`, ``angle_max``,
``angle_increment`` [rad], ``range_min``, ``range_max`` [m] and :meth:`LidarScanner.scan`'s
ranges. The caller sets ``scan_time`` to the period it publishes at [s] (``1 / rate_hz`` at
the manifest's nominal rate) and ``time_increment`` to 0: every ray of a simulated scan is
cast at the same simulated instant.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Collection

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import LidarSensor

VISIBLE_GROUPS = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8)
"""Geom groups a lidar sees: MuJoCo's default ``mjvOption.geomgroup`` (groups 0 to 2)."""

HIDDEN_GROUP = 5
"""Group the scanner's copy of the model moves excluded geoms to (not visible)."""

Ranges = npt.NDArray[np.float32]


class LidarScanner:
    """Casts one lidar sensor's scans in a scene (see the module doc)."""

    def __init__(
        self, model: mujoco.MjModel, sensor: LidarSensor, excluded_bodies: Collection[int]
    ) -> None:
        """Precompute the site, the rays in the site frame and the ray-casting model.

        Args:
            model: The composed scene.
            sensor: The manifest sensor (site, rays, range).
            excluded_bodies: Body ids the lidar must not see (the robot's own bodies).

        Raises:
            ValueError: ``sensor.site`` is not a site of ``model``, or its range is empty.
        """
        self.sensor = sensor
        self.site_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, sensor.site)
        if self.site_id < 0:
            raise ValueError(f"lidar sensor {sensor.name!r}: the scene has no site {sensor.site!r}")
        low, high = (float(v) for v in sensor.range_m)
        if not 0.0 <= low <= high:
            raise ValueError(f"lidar sensor {sensor.name!r}: range_m {[low, high]} is empty")
        self.range_min = low
        """Shortest distance measured [m]; closer hits read ``-inf``."""
        self.range_max = high
        """Longest distance measured [m]; farther hits, and no hit, read ``+inf``."""
        self.width = sensor.width
        first, last = (math.radians(float(a)) for a in sensor.angle_range_deg)
        angles = np.linspace(first, last, self.width)
        self.angle_min = first
        """Angle of the first ray about the site's z axis [rad], 0 along its x axis."""
        self.angle_max = float(angles[-1])
        """Angle of the last ray [rad] (``angle_min`` for a single ray)."""
        self.angle_increment = (last - first) / (self.width - 1) if self.width > 1 else 0.0
        """Angle between neighbouring rays [rad] (0 for a single ray)."""
        self.directions = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], 1)
        """``width`` x 3 unit ray directions in the site frame."""
        self.excluded_geoms = np.isin(model.geom_bodyid, np.fromiter(excluded_bodies, int))
        """Per geom of ``model``: on an excluded body (never seen)."""
        self._model = ray_model(model, self.excluded_geoms)
        self._world = np.empty((self.width, 3))
        self._geom = np.empty(self.width, dtype=np.int32)
        self._dist = np.empty(self.width)

    def scan(self, data: mujoco.MjData) -> Ranges:
        """Cast one scan of ``data``'s state.

        Args:
            data: The scene's data, kinematics current (after ``mj_forward`` or
                ``mj_step``); only its stack is written, for the duration of the cast.

        Returns:
            ``width`` ranges [m] in ray order (``-inf``/``+inf`` as in the module doc).

        Raises:
            ValueError: ``data`` belongs to a model with another number of geoms.
        """
        if data.geom_xpos.shape[0] != self._model.ngeom:
            raise ValueError(
                f"lidar sensor {self.sensor.name!r}: data has {data.geom_xpos.shape[0]} geoms,"
                f" the scene {self._model.ngeom}"
            )
        rotation = data.site_xmat[self.site_id].reshape(3, 3)
        np.matmul(self.directions, rotation.T, out=self._world)
        mujoco.mj_multiRay(
            self._model,
            data,
            data.site_xpos[self.site_id],
            self._world.reshape(-1),
            VISIBLE_GROUPS,
            True,
            -1,
            self._geom,
            self._dist,
            None,
            self.width,
            math.inf,
        )
        return to_ranges(self._dist, self.range_min, self.range_max)


def ray_model(model: mujoco.MjModel, hidden: npt.NDArray[np.bool_]) -> mujoco.MjModel:
    """A copy of ``model`` for ray casting: the ``hidden`` geoms moved to
    :data:`HIDDEN_GROUP`, and ``mj_multiRay``'s per-body culling off (see the module doc)."""
    rays = copy.copy(model)
    rays.geom_group[hidden] = HIDDEN_GROUP
    rays.body_bvhadr[:] = -1
    return rays


def to_ranges(dist: npt.NDArray[np.float64], range_min: float, range_max: float) -> Ranges:
    """REP 117 ranges [m] of ray-cast distances (``-1``: no hit): ``+inf`` for no hit or one
    beyond ``range_max``, ``-inf`` for one closer than ``range_min``."""
    ranges = dist.astype(np.float32)
    ranges[(dist < 0.0) | (dist > range_max)] = np.inf
    ranges[(dist >= 0.0) & (dist < range_min)] = -np.inf
    return ranges
