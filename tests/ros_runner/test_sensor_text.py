"""Depth images, point clouds and laser scans as ``openral ros echo`` and ``snapshot`` read
them: decoded from the bridge's own packers and from hand-made messages."""

from __future__ import annotations

import numpy as np
import pytest
from openral_bridge.ros_messages import image_msg, laser_scan_msg, point_cloud_msg, stamp
from openral_nodes.topic_codec import (
    ImageEncodingError,
    cloud_points,
    depth_colours,
    depth_metres,
)
from openral_nodes.topic_format import format_message, sensor_summary
from sensor_msgs.msg import Image, PointCloud2, PointField

DEPTH = np.array([[0.5, np.nan, 1.25], [2.0, 0.75, np.nan]], dtype=np.float32)


def test_a_32fc1_depth_image_round_trips_through_the_bridge_packer() -> None:
    np.testing.assert_array_equal(depth_metres(image_msg(DEPTH, stamp(1.0), "d")), DEPTH)


def test_a_16uc1_image_is_millimetres_with_zero_as_no_reading() -> None:
    millimetres = np.array([[500, 0], [1250, 65535]], dtype=">u2")
    msg = Image(height=2, width=2, encoding="16UC1", step=4, is_bigendian=True)
    msg.data = millimetres.tobytes()
    expected = np.array([[0.5, np.nan], [1.25, 65.535]], dtype=np.float32)
    np.testing.assert_allclose(depth_metres(msg), expected, rtol=1e-6)


def test_depth_colours_run_from_warm_near_to_cool_far_and_black_for_none() -> None:
    rgb = depth_colours(DEPTH)
    assert rgb.shape == (2, 3, 3) and rgb.dtype == np.uint8
    assert (rgb[0, 1] == 0).all() and (rgb[1, 2] == 0).all()
    near, far = rgb[0, 0].astype(int), rgb[1, 0].astype(int)
    assert near[0] > far[0] and near[1] > far[1]  # yellow near, purple far
    assert (depth_colours(np.full((2, 2), np.nan)) == 0).all()


def test_a_cloud_round_trips_and_a_padded_one_is_read_by_its_fields() -> None:
    points = np.array([[0.1, -0.2, 0.3], [1.0, 2.0, -3.0]], dtype=np.float32)
    np.testing.assert_array_equal(cloud_points(point_cloud_msg(points, stamp(0.1), "b")), points)
    padded = PointCloud2(height=1, width=2, point_step=16, row_step=32, is_bigendian=False)
    padded.fields = [
        PointField(name=a, offset=o, datatype=PointField.FLOAT32, count=1)
        for a, o in (("z", 0), ("x", 4), ("y", 12))
    ]
    rows = np.zeros((2, 4), np.float32)
    rows[:, 0], rows[:, 1], rows[:, 3], rows[:, 2] = points[:, 2], points[:, 0], points[:, 1], 9
    padded.data = rows.tobytes()
    np.testing.assert_array_equal(cloud_points(padded), points)


@pytest.mark.parametrize(
    ("point_step", "size", "fields", "message"),
    [
        (12, 20, "xyz", "malformed point cloud: 2 points of 12 bytes, 20 data bytes"),
        (8, 24, "xyz", "malformed point cloud"),
        (12, 24, "xy", r"without FLOAT32 field\(s\) z"),
    ],
)
def test_a_malformed_cloud_is_one_clear_line(
    point_step: int, size: int, fields: str, message: str
) -> None:
    msg = PointCloud2(height=1, width=2, point_step=point_step, data=bytes(size))
    msg.fields = [
        PointField(name=a, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, a in enumerate(fields)
    ]
    with pytest.raises(ImageEncodingError, match=message):
        cloud_points(msg)
    assert sensor_summary(msg) is not None and "point cloud" in str(sensor_summary(msg))


def test_echo_starts_with_what_a_sensor_message_holds() -> None:
    cloud = point_cloud_msg(np.array([[0, 0, 0], [1, -2, 3]], np.float32), stamp(2.0), "base")
    assert format_message(cloud).startswith(
        "# 2 points, x [0.0, 1.0], y [-2.0, 0.0], z [0.0, 3.0] m\n"
    )
    scan = laser_scan_msg(
        np.array([1.5, np.inf, 0.25, -np.inf]),
        angle_range_rad=(-1.0, 1.0),
        range_m=(0.1, 10.0),
        scan_time_s=0.1,
        stamp_msg=stamp(2.0),
        frame_id="lidar",
    )
    assert format_message(scan).startswith(
        "# 4 beams, range 0.25 to 1.5 m, 1 without a return (+inf), 1 too close (-inf)\n"
    )
    depth = format_message(image_msg(DEPTH, stamp(2.0), "d"))
    assert depth.startswith("# 3x2 depth image, depth 0.5 to 2.0 m, 2 pixels without one\n")
    assert sensor_summary(image_msg(np.zeros((2, 2, 3), np.uint8), stamp(2.0), "c")) is None
