"""The TF frame tree of a simulated robot and its sensors, read from the live MuJoCo data.

Frames (every name from the model or the manifest):

- the world frame (``FrameNames.world``), MuJoCo's world;
- the robot's tree (:mod:`openral_mujoco.robot_tree`): its base frame, under the world
  (fixed, or moving on a floating base) or under the odometry frame of a mobile base
  (``FrameNames.odom``, fixed in the world where the base frame was at the last reset), and
  every body of the robot under its parent;
- one frame per sensor the scene serves, named by its ``frame_id``: a camera's optical frame
  (REP 103: z forward, x right, y down; MuJoCo's camera looks along -z with y up, so the
  optical frame is the camera turned half a turn about x) and a lidar's, IMU's,
  force-torque or pose sensor's site frame, each under the link of the body it sits on, or
  under the world when that body is not the robot's.

A transform that cannot change between resets is **static** (``/tf_static``): a link fixed
to its parent, the odometry frame, a sensor fixed on a link or in the world. Every other
one is **dynamic** (``/tf``). :meth:`FrameTree.sample` reads the world pose of every frame
from one ``MjData`` (a handful of array copies, meant to be taken under the HAL's lock right
after a step) and :meth:`FrameSample.relative` turns them into parent → child transforms,
so each transform equals MuJoCo's poses to rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import SiteSensor
from openral_core.tables import FrameNames
from openral_mujoco.errors import HalError
from openral_mujoco.robot_addresses import RobotAddresses
from openral_mujoco.robot_tree import BaseKind, RobotTree, robot_tree
from openral_mujoco.state import FloatArray

from openral_sim.base_drive import BaseDrive

IntArray = npt.NDArray[np.intp]
OPTICAL = np.array([0.0, 1.0, 0.0, 0.0])
"""Half a turn about x (w, x, y, z): a MuJoCo camera frame → its REP 103 optical frame."""
CAMERA_LINK = np.array([0.5, -0.5, 0.5, 0.5])
"""A MuJoCo camera frame → its camera link (x forward = -z, y left = -x, z up = y)."""
OPTICAL_SUFFIX = "_optical_frame"
"""A camera frame_id ending so gets a camera link named with ``_link`` instead."""


class FrameTreeError(HalError):
    """Two frames share a name, or a sensor's frame cannot be placed."""


@dataclass(frozen=True)
class SensorFrame:
    """Where one sensor's frame is in the model: a camera (optical frame) or a site."""

    frame_id: str
    camera: int = -1
    site: int = -1
    parent: str = ""
    """The frame it hangs from ("": the link of its body, or the world)."""
    body_axes: bool = False
    """A camera's link (REP 103 body axes: x forward, z up) instead of its optical frame."""


@dataclass(frozen=True)
class Frame:
    """One frame of the tree and how its world pose is read."""

    name: str
    parent: str
    static: bool


@dataclass(frozen=True)
class FrameSample:
    """World poses of every frame at one instant (see :meth:`FrameTree.sample`)."""

    sim_time_s: float
    positions: FloatArray
    """(frames, 3) world positions [m], in :attr:`FrameTree.frames` order."""
    quats: FloatArray
    """(frames, 4) world orientations (w, x, y, z)."""

    def relative(self, tree: FrameTree, which: IntArray) -> tuple[FloatArray, FloatArray]:
        """(positions, quaternions) of frames ``which`` in their parents' frames."""
        return in_parent_frames(self.positions, self.quats, which, tree.parent_index[which])


class FrameTree:
    """Every frame of a simulated robot, its sensors and the world (see the module doc)."""

    def __init__(
        self,
        model: mujoco.MjModel,
        names: FrameNames,
        tree: RobotTree,
        sensors: list[SensorFrame],
        base: BaseDrive | None = None,
    ) -> None:
        """Lay the frames out (parents before children).

        Args:
            model: The composed model the tree and the sensors were read from.
            names: The world, base and odometry frame names.
            tree: The robot's tree in ``model``.
            sensors: The sensors' frames.
            base: The mobile base's drive (its odometry frame's origin); None without one.

        Raises:
            FrameTreeError: Two frames share a name.
        """
        self.model, self.tree, self.names, self.base = model, tree, names, base
        self.root_in_base = _root_origin(tree)
        """The root body's pose in the base frame (position [m], quaternion w, x, y, z)."""
        self._base_in_root = _inverse_pose(self.root_in_base)
        frames: list[Frame] = [Frame(names.world, "", True), *self._base_frames()]
        link_of = {link.body: link.name for link in tree.links if link.body >= 0}
        body_rows, bodies, extras = [], [], []
        for link in tree.links:
            if link.parent is not None and link.body < 0:  # an extra link: off its parent
                extras.append((len(frames), link))
                frames.append(Frame(link.name, link.parent, True))
            elif link.parent is not None:
                body_rows.append(len(frames))
                bodies.append(link.body)
                frames.append(Frame(link.name, link.parent, link.joint is None))
        self._body_rows = np.array(body_rows, dtype=np.intp)
        self._bodies = np.array(bodies, dtype=np.intp)
        self._sensors: list[tuple[int, SensorFrame]] = []
        for sensor in sensors:
            self._sensors.append((len(frames), sensor))
            frames.append(self._sensor_frame(sensor, link_of))
        self.frames = tuple(frames)
        self._check_unique()
        index = {frame.name: i for i, frame in enumerate(frames)}
        self.parent_index = np.array([index.get(f.parent, 0) for f in frames], dtype=np.intp)
        self._extras = [
            (row, index[link.parent or ""], np.array(link.position), np.array(link.quat))
            for row, link in extras
        ]
        """Extra links (``frames.extra_links``), parents first: (row, parent row, pose in
        the parent)."""
        self.static = np.array([i for i, f in enumerate(frames) if f.static and i], np.intp)
        self.dynamic = np.array([i for i, f in enumerate(frames) if not f.static], np.intp)

    @property
    def sensor_rows(self) -> tuple[int, ...]:
        """The rows of the sensors' frames in :attr:`frames`, in order."""
        return tuple(row for row, _ in self._sensors)

    @property
    def names_of_frames(self) -> tuple[str, ...]:
        """Every frame's name, the world first."""
        return tuple(frame.name for frame in self.frames)

    def sample(self, data: mujoco.MjData) -> FrameSample:
        """World pose of every frame as ``data`` holds them (copies; hold the HAL's lock)."""
        count = len(self.frames)
        positions, quats = np.zeros((count, 3)), np.zeros((count, 4))
        quats[0, 0] = 1.0
        base = self.base_pose(data)
        positions[self._base_row], quats[self._base_row] = base
        if self._odom_row is not None and self.base is not None:
            x, y, heading = self.base.origin
            positions[self._odom_row] = (x, y, base[0][2])
            quats[self._odom_row] = (np.cos(heading / 2), 0.0, 0.0, np.sin(heading / 2))
        positions[self._body_rows] = data.xpos[self._bodies]
        quats[self._body_rows] = data.xquat[self._bodies]
        for row, parent, position, quat in self._extras:
            mujoco.mju_mulPose(
                positions[row], quats[row], positions[parent], quats[parent], position, quat
            )
        for row, sensor in self._sensors:
            positions[row], quats[row] = _sensor_pose(data, sensor)
        return FrameSample(float(data.time), positions, quats)

    # -- layout ------------------------------------------------------------------------------

    def _base_frames(self) -> list[Frame]:
        """The base frame (and a mobile base's odometry frame before it); a base frame that is
        the root body itself is laid out here too (its link has no parent)."""
        tree, names = self.tree, self.names
        self._odom_row: int | None = None
        if tree.kind is BaseKind.MOBILE and self.base is not None and names.odom is not None:
            self._odom_row, self._base_row = 1, 2
            return [Frame(names.odom, names.world, True), Frame(tree.base, names.odom, False)]
        self._base_row = 1
        return [Frame(tree.base, names.world, tree.kind is BaseKind.FIXED)]

    def base_pose(self, data: mujoco.MjData) -> tuple[FloatArray, FloatArray]:
        """The base frame's world pose (position [m], quaternion w, x, y, z): the root
        body's, less its origin in the base frame."""
        root, (position, quat) = self.tree.root, self._base_in_root
        world, world_quat = np.empty(3), np.empty(4)
        mujoco.mju_mulPose(world, world_quat, data.xpos[root], data.xquat[root], position, quat)
        return world, world_quat

    def _sensor_frame(self, sensor: SensorFrame, link_of: dict[int, str]) -> Frame:
        model = self.model
        if sensor.camera >= 0:
            body = int(model.cam_bodyid[sensor.camera])
            fixed_mount = model.cam_mode[sensor.camera] == mujoco.mjtCamLight.mjCAMLIGHT_FIXED
        elif sensor.site >= 0:
            body = int(model.site_bodyid[sensor.site])
            fixed_mount = True
        else:
            raise FrameTreeError(f"frame {sensor.frame_id!r} has neither a camera nor a site")
        parent = sensor.parent or link_of.get(body, self.names.world)
        on_world = body == 0 or int(model.body_weldid[body]) == 0
        static = fixed_mount and (body in link_of or on_world)
        return Frame(sensor.frame_id, parent, static)

    def _check_unique(self) -> None:
        seen: set[str] = set()
        for frame in self.frames:
            if frame.name in seen:
                raise FrameTreeError(
                    f"two frames are called {frame.name!r} (a body of the model, a sensor's "
                    "frame_id, or the world, base or odometry frame); frame names must differ"
                )
            seen.add(frame.name)


def scene_frame_tree(
    model: mujoco.MjModel,
    robot: LoadedRobot,
    addresses: RobotAddresses,
    cameras: dict[str, str],
    base: BaseDrive | None,
) -> FrameTree:
    """The frame tree of ``robot`` in a composed ``model``: its tree, and a frame for every
    camera sensor in ``cameras`` (sensor → MJCF camera) and every site sensor whose site the
    model has.

    Raises:
        HalError: See :class:`FrameTree` and :func:`~openral_mujoco.robot_tree.robot_tree`.
    """
    tree = robot_tree(model, robot.description, robot.tables, addresses)
    taken = {link.name for link in tree.links} | {s.frame_id for s in robot.description.sensors}
    sensors = []
    for sensor in robot.description.sensors:
        if sensor.name in cameras:
            camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, cameras[sensor.name])
            link = camera_link(sensor.frame_id)
            if link is not None and link not in taken:  # camera link, then its optical frame
                taken.add(link)
                sensors.append(SensorFrame(link, camera=camera, body_axes=True))
            sensors.append(SensorFrame(sensor.frame_id, camera=camera, parent=link or ""))
        elif isinstance(sensor, SiteSensor):
            site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, sensor.site)
            if site >= 0:
                sensors.append(SensorFrame(sensor.frame_id, site=site))
    return FrameTree(model, robot.tables.frames, tree, sensors, base)


def camera_link(frame_id: str) -> str | None:
    """The camera link of an optical frame ``<name>_optical_frame``: ``<name>_link``."""
    if not frame_id.endswith(OPTICAL_SUFFIX) or frame_id == OPTICAL_SUFFIX:
        return None
    return frame_id[: -len(OPTICAL_SUFFIX)] + "_link"


# -- poses -----------------------------------------------------------------------------------


def _root_origin(tree: RobotTree) -> tuple[FloatArray, FloatArray]:
    """The root body's pose in the base frame (identity when the root is the base)."""
    for link in tree.links:
        if link.body == tree.root:
            return np.array(link.position, dtype=np.float64), np.array(link.quat, dtype=np.float64)
    raise FrameTreeError("the robot's tree has no root body")


def _inverse_pose(pose: tuple[FloatArray, FloatArray]) -> tuple[FloatArray, FloatArray]:
    position, quat = np.empty(3), np.empty(4)
    mujoco.mju_negPose(position, quat, pose[0], pose[1])
    return position, quat


def _sensor_pose(data: mujoco.MjData, sensor: SensorFrame) -> tuple[FloatArray, FloatArray]:
    """A camera's optical frame, or a site's frame, in the world."""
    quat = np.empty(4)
    if sensor.camera >= 0:
        mujoco.mju_mat2Quat(quat, data.cam_xmat[sensor.camera])
        turned = np.empty(4)
        mujoco.mju_mulQuat(turned, quat, CAMERA_LINK if sensor.body_axes else OPTICAL)
        return np.array(data.cam_xpos[sensor.camera]), turned
    mujoco.mju_mat2Quat(quat, data.site_xmat[sensor.site])
    return np.array(data.site_xpos[sensor.site]), quat


def pose_in_frame(
    frame: tuple[FloatArray, FloatArray], pose: tuple[FloatArray, FloatArray]
) -> tuple[FloatArray, FloatArray]:
    """A world ``pose`` (position [m], quaternion w, x, y, z) in the frame whose world pose
    is ``frame`` (one pose: MuJoCo's quaternion routines; :meth:`FrameSample.relative` does
    the same for many rows)."""
    inverse, position, quat = np.empty(4), np.empty(3), np.empty(4)
    mujoco.mju_negQuat(inverse, frame[1])
    mujoco.mju_rotVecQuat(position, np.asarray(pose[0]) - frame[0], inverse)
    mujoco.mju_mulQuat(quat, inverse, np.asarray(pose[1]))
    return position, quat


def in_parent_frames(
    positions: FloatArray, quats: FloatArray, children: IntArray, parents: IntArray
) -> tuple[FloatArray, FloatArray]:
    """(positions [m], quaternions w, x, y, z) of the world poses in rows ``children`` of
    ``positions``/``quats``, each in the frame of the same entry of ``parents``."""
    inverse = _conjugate(quats[parents])
    offset = positions[children] - positions[parents]
    return _rotate(inverse, offset), _multiply(inverse, quats[children])


# -- quaternions (w, x, y, z), one per row ---------------------------------------------------


def _conjugate(q: FloatArray) -> FloatArray:
    out: FloatArray = q * np.array([1.0, -1.0, -1.0, -1.0])
    return out


def _multiply(a: FloatArray, b: FloatArray) -> FloatArray:
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    out: FloatArray = np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )
    return out


def _rotate(q: FloatArray, v: FloatArray) -> FloatArray:
    """Each row of ``v`` turned by the unit quaternion in the same row of ``q``
    (``v + w t + u x t`` with ``t = 2 u x v``; cross products written out, a tenth of
    ``np.cross``'s time on a few rows)."""
    w = q[:, :1]
    u = q[:, 1:]
    t = 2.0 * _cross(u, v)
    out: FloatArray = v + w * t + _cross(u, t)
    return out


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """Row-wise cross product of two (n, 3) arrays."""
    ax, ay, az = a.T
    bx, by, bz = b.T
    out: FloatArray = np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=1)
    return out
