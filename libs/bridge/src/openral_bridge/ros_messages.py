"""numpy → ROS 2 message packing (cv_bridge and sensor_msgs_py are not on PyPI).

Pure functions, no node needed: images (rgb8, 32FC1 depth), pinhole camera info from a
vertical field of view, joint states, laser scans and xyz point clouds.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
from builtin_interfaces.msg import Time
from openral_sim.depth_cloud import focal_length_px
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import (
    CameraInfo,
    Image,
    JointState,
    LaserScan,
    PointCloud2,
    PointField,
)

LATCHED = QoSProfile(  # type: ignore[no-untyped-call]
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
"""Latched QoS (transient local, reliable, depth 1), as a latched ROS publisher offers it:
a late subscriber still gets the last message (``/openral/action_spec``,
``/robot_description``, ``/tf_static``)."""

FloatArray = npt.NDArray[np.floating[Any]]


def stamp(seconds: float) -> Any:
    """``builtin_interfaces/Time`` of ``seconds`` (non-negative) [s]."""
    nanoseconds = max(0, round(seconds * 1e9))
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def image_msg(image: npt.NDArray[Any], stamp_msg: Any, frame_id: str) -> Any:
    """``sensor_msgs/Image`` of an HxWx3 uint8 (``rgb8``) or HxW float32 (``32FC1``) array.

    Raises:
        ValueError: Any other shape or dtype.
    """
    array = np.ascontiguousarray(image)
    if array.ndim == 3 and array.shape[2] == 3 and array.dtype == np.uint8:
        encoding, channels = "rgb8", 3
    elif array.ndim == 2 and array.dtype == np.float32:
        encoding, channels = "32FC1", 1
    else:
        raise ValueError(
            f"image of shape {array.shape} and dtype {array.dtype}; expected HxWx3 uint8 "
            "(rgb8) or HxW float32 (32FC1)"
        )
    height, width = array.shape[:2]
    msg = Image()
    msg.header.stamp = stamp_msg
    msg.header.frame_id = frame_id
    msg.height, msg.width, msg.encoding = height, width, encoding
    msg.is_bigendian = int(np.little_endian is False)
    msg.step = width * channels * array.itemsize
    msg.data = array.tobytes()
    return msg


def camera_info_msg(width: int, height: int, fovy_deg: float, stamp_msg: Any, frame_id: str) -> Any:
    """``sensor_msgs/CameraInfo`` of an ideal pinhole (MuJoCo's camera model).

    Square pixels (:func:`~openral_sim.depth_cloud.focal_length_px`, the focal length the
    depth clouds use too), principal point at the image centre, no distortion; ROS puts
    pixel centres on integer coordinates, so the centre is
    ``((width - 1) / 2, (height - 1) / 2)``.

    Args:
        width: Image width [px].
        height: Image height [px].
        fovy_deg: Vertical field of view [deg].
    """
    focal = focal_length_px(height, fovy_deg)
    cx, cy = (width - 1) / 2.0, (height - 1) / 2.0
    msg = CameraInfo()
    msg.header.stamp = stamp_msg
    msg.header.frame_id = frame_id
    msg.width, msg.height = width, height
    msg.distortion_model = "plumb_bob"
    msg.d = [0.0] * 5
    msg.k = [focal, 0.0, cx, 0.0, focal, cy, 0.0, 0.0, 1.0]
    msg.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    msg.p = [focal, 0.0, cx, 0.0, 0.0, focal, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return msg


def joint_state_msg(
    names: Sequence[str],
    positions: FloatArray,
    velocities: FloatArray,
    efforts: FloatArray,
    stamp_msg: Any,
) -> Any:
    """``sensor_msgs/JointState`` with one entry per name [rad or m, /s, N·m or N]."""
    msg = JointState()
    msg.header.stamp = stamp_msg
    msg.name = list(names)
    msg.position = np.asarray(positions, dtype=np.float64).tolist()
    msg.velocity = np.asarray(velocities, dtype=np.float64).tolist()
    msg.effort = np.asarray(efforts, dtype=np.float64).tolist()
    return msg


def laser_scan_msg(
    ranges: FloatArray,
    *,
    angle_range_rad: tuple[float, float],
    range_m: tuple[float, float],
    scan_time_s: float,
    stamp_msg: Any,
    frame_id: str,
) -> Any:
    """``sensor_msgs/LaserScan`` of evenly spaced beams from ``angle_range_rad[0]`` on.

    Beams with no return carry ``inf`` (REP 117).
    """
    values = np.asarray(ranges, dtype=np.float32).ravel()
    low, high = angle_range_rad
    msg = LaserScan()
    msg.header.stamp = stamp_msg
    msg.header.frame_id = frame_id
    msg.angle_min, msg.angle_max = float(low), float(high)
    msg.angle_increment = float((high - low) / max(1, values.size - 1))
    msg.scan_time = float(scan_time_s)
    msg.time_increment = 0.0
    msg.range_min, msg.range_max = float(range_m[0]), float(range_m[1])
    msg.ranges = values.tolist()
    return msg


def point_cloud_msg(points: FloatArray, stamp_msg: Any, frame_id: str) -> Any:
    """Unorganised ``sensor_msgs/PointCloud2`` with float32 x, y, z fields [m].

    Raises:
        ValueError: ``points`` is not N x 3.
    """
    xyz = np.ascontiguousarray(points, dtype=np.float32)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise ValueError(f"points of shape {xyz.shape}; expected N x 3")
    msg = PointCloud2()
    msg.header.stamp = stamp_msg
    msg.header.frame_id = frame_id
    msg.height, msg.width = 1, xyz.shape[0]
    msg.fields = [
        PointField(name=axis, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, axis in enumerate("xyz")
    ]
    msg.is_bigendian = not np.little_endian
    msg.point_step = 12
    msg.row_step = 12 * xyz.shape[0]
    msg.is_dense = bool(np.isfinite(xyz).all())
    msg.data = xyz.tobytes()
    return msg
