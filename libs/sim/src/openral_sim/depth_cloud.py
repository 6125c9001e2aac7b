"""Depth images and self-filtered point clouds of a native scene's depth sensors.

A manifest :class:`~openral_core.models.DepthSensor` renders from its scene camera at its own
``width`` x ``height``. Each frame takes two offscreen passes of the same scene state:

- depth, which MuJoCo's renderer already converts to metres along the optical axis (the
  ROS depth-image convention, REP 118). Pixels outside the sensor's ``range_m`` become NaN,
  and so does the sky;
- segmentation, which gives the geom seen at each pixel.

The cloud is the depth image back-projected through the camera's pinhole (square pixels,
vertical field of view ``cam_fovy``) and expressed in the robot's base frame (its root
body). It leaves out the robot: every pixel that shows one of the robot's geoms, and every
other point closer to a point of the robot the camera sees than :data:`SELF_MARGIN_M` plus
one pixel's diagonal at the farthest such robot point (the camera knows the robot's surface
only to its pixel size, so that much is added). A collision checker fed this cloud never
sees the arm it is checking, nor the rim where the arm meets its pedestal or an object it
touches. The margin test is exact: a voxel grid of the margin's size picks the candidates,
then their distances to the robot's points are computed in bounded chunks.

What counts as the robot: every geom on a body under a world child that carries a
manifest joint (:func:`~openral_sim.scene_geometry.robot_bodies`), as far as the camera
renders it (the model's visible geom groups).
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import DepthSensor

from openral_sim.gl_guard import gl_turn

SELF_MARGIN_M = 0.01
"""Points closer than this to the robot's own visible surface leave the cloud [m]."""

CHUNK = 4096
"""Cloud points compared with the robot's points at a time (bounds memory)."""

Depth = npt.NDArray[np.float32]
Points = npt.NDArray[np.float32]


@dataclass(frozen=True)
class DepthFrame:
    """One frame of a depth sensor.

    Attributes:
        depth_m: H x W distance along the optical axis [m], NaN outside ``range_m``.
        points: N x 3 cloud in the robot's base frame [m] (robot and margin left out).
        sim_time_s: Simulated time of the state it shows [s].
    """

    depth_m: Depth
    points: Points
    sim_time_s: float


class DepthCamera:
    """Renders one depth sensor from its scene camera and builds its cloud."""

    def __init__(
        self,
        model: mujoco.MjModel,
        sensor: DepthSensor,
        camera: str,
        robot: Collection[int],
        base_body: int,
        margin_m: float = SELF_MARGIN_M,
    ) -> None:
        """Precompute the pixel rays and the robot's geoms.

        Args:
            model: The composed scene.
            sensor: The manifest sensor (size, range).
            camera: Its MJCF camera in ``model``.
            robot: Body ids of the robot (see the module doc).
            base_body: The body whose frame the cloud is given in.
            margin_m: Points this close to the robot's seen surface leave the cloud [m].

        Raises:
            ValueError: ``camera`` is not a camera of ``model``.
        """
        self.sensor = sensor
        self.camera_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        if self.camera_id < 0:
            raise ValueError(f"depth sensor {sensor.name!r}: the scene has no camera {camera!r}")
        self.height, self.width = sensor.height, sensor.width
        low, high = sensor.range_m or (0.0, math.inf)
        self.range_m = (float(low), float(high))
        self.base_body = base_body
        self.margin_m = margin_m
        self.robot_geoms = np.isin(model.geom_bodyid, list(robot))
        self.fovy_deg = float(model.cam_fovy[self.camera_id])
        self.focal_px = focal_length_px(self.height, self.fovy_deg)
        self._rays = pixel_rays(self.height, self.width, self.focal_px)

    def render(
        self, renderer: mujoco.Renderer, data: mujoco.MjData
    ) -> tuple[Depth, npt.NDArray[np.int32]]:
        """Depth [m] (raw, before the range) and the geom id seen at each pixel (-1: none),
        from a renderer of this sensor's size; ``data`` is only read."""
        with gl_turn():
            renderer.update_scene(data, camera=self.camera_id)
            renderer.enable_depth_rendering()
            try:
                depth = renderer.render().copy()
            finally:
                renderer.disable_depth_rendering()
            renderer.enable_segmentation_rendering()
            try:
                segments = renderer.render()
            finally:
                renderer.disable_segmentation_rendering()
        is_geom = segments[:, :, 1] == int(mujoco.mjtObj.mjOBJ_GEOM)
        geoms = np.where(is_geom, segments[:, :, 0], -1).astype(np.int32)
        return depth, geoms

    def frame(self, renderer: mujoco.Renderer, data: mujoco.MjData) -> DepthFrame:
        """Render and build one :class:`DepthFrame` of ``data``'s state."""
        depth, geoms = self.render(renderer, data)
        return self.frame_from(depth, geoms, data)

    def frame_from(
        self, depth: Depth, geoms: npt.NDArray[np.int32], data: mujoco.MjData
    ) -> DepthFrame:
        """The frame of a rendered depth and segmentation pair (see :meth:`render`)."""
        low, high = self.range_m
        in_range = (depth >= low) & (depth <= high) & (geoms >= 0)
        robot = (geoms >= 0) & self.robot_geoms[np.maximum(geoms, 0)]
        camera_points = self._rays * depth[:, :, None]
        to_base = _camera_to_base(data, self.camera_id, self.base_body)
        seen = _transform(to_base, camera_points[in_range & ~robot])
        body_pixels = robot & np.isfinite(depth)
        body = _transform(to_base, camera_points[body_pixels])
        margin = self.margin_m
        if body_pixels.any():  # a pixel's diagonal at the farthest robot point seen
            margin += math.sqrt(2.0) * float(depth[body_pixels].max()) / self.focal_px
        kept = seen[~near_any(seen, body, margin)]
        image = np.where(in_range, depth, np.float32(np.nan)).astype(np.float32)
        return DepthFrame(image, kept.astype(np.float32), float(data.time))


def focal_length_px(height: int, fovy_deg: float) -> float:
    """Focal length [px] of a pinhole with vertical field of view ``fovy_deg``."""
    return 0.5 * height / math.tan(math.radians(fovy_deg) / 2)


def pixel_rays(height: int, width: int, focal_px: float) -> npt.NDArray[np.float64]:
    """H x W x 3 camera-frame points at unit depth through each pixel centre (MuJoCo's
    camera frame: x right, y up, looking along -z; row 0 is the top of the image)."""
    u = (np.arange(width) + 0.5 - width / 2) / focal_px
    v = (np.arange(height) + 0.5 - height / 2) / focal_px
    rays = np.empty((height, width, 3))
    rays[:, :, 0] = u[None, :]
    rays[:, :, 1] = -v[:, None]
    rays[:, :, 2] = -1.0
    return rays


def near_any(points: Points, others: Points, margin: float) -> npt.NDArray[np.bool_]:
    """For each of ``points``, whether some point of ``others`` is closer than ``margin``.

    Only pairs in the same or neighbouring voxels of size ``margin`` are compared (a closer
    pair always is), ``CHUNK`` points at a time, so time and memory follow the number of
    such pairs, not ``len(points) * len(others)``.
    """
    near = np.zeros(len(points), dtype=bool)
    if not len(points) or not len(others):
        return near
    box = np.all((points > others.min(axis=0) - margin) & (points < others.max(axis=0) + margin), 1)
    if not box.all():  # only points in the others' bounding box (grown by margin) can be near
        near[box] = near_any(points[box], others, margin)
        return near
    other_keys = _voxel_keys(np.floor(others / margin).astype(np.int64))
    order = np.argsort(other_keys, kind="stable")
    sorted_keys = other_keys[order]
    cells = np.floor(points / margin).astype(np.int64)
    for start in range(0, len(points), CHUNK):
        rows = np.arange(start, min(start + CHUNK, len(points)))
        for offset in _NEIGHBOURS:
            keys = _voxel_keys(cells[rows] + offset)
            low = np.searchsorted(sorted_keys, keys, side="left")
            counts = np.searchsorted(sorted_keys, keys, side="right") - low
            pick = (counts > 0) & ~near[rows]
            if not pick.any():
                continue
            count = counts[pick]
            first = np.repeat(low[pick], count)
            step = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
            pair_rows = np.repeat(rows[pick], count)
            gaps = points[pair_rows].astype(np.float64) - others[order[first + step]]
            near[pair_rows[np.einsum("ij,ij->i", gaps, gaps) < margin * margin]] = True
    return near


_NEIGHBOURS = np.array([(x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1)])


def _voxel_keys(cells: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """One integer per voxel (cells within ±2^20 of the origin, ±10 km at 1 cm)."""
    shifted = cells + (1 << 20)
    return (shifted[:, 0] << 42) | (shifted[:, 1] << 21) | shifted[:, 2]


def _camera_to_base(
    data: mujoco.MjData, camera: int, base: int
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(R, t) taking camera-frame points to the base body's frame."""
    base_rotation = data.xmat[base].reshape(3, 3)
    camera_rotation = data.cam_xmat[camera].reshape(3, 3)
    rotation = base_rotation.T @ camera_rotation
    translation = base_rotation.T @ (data.cam_xpos[camera] - data.xpos[base])
    return rotation, translation


def _transform(
    pose: tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]], points: npt.NDArray[np.float64]
) -> Points:
    rotation, translation = pose
    return (points @ rotation.T + translation).astype(np.float32)
