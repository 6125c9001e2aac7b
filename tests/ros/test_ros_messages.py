"""Tests for ros_messages.py: numpy arrays packed into sensor_msgs, checked by unpacking."""

from __future__ import annotations

import math

import numpy as np
import pytest
from openral_bridge.ros_messages import (
    camera_info_msg,
    image_msg,
    joint_state_msg,
    laser_scan_msg,
    point_cloud_msg,
    stamp,
)


def test_stamp_splits_seconds_and_nanoseconds() -> None:
    t = stamp(12.000000123)
    assert (t.sec, t.nanosec) == (12, 123)
    assert (stamp(-1.0).sec, stamp(-1.0).nanosec) == (0, 0)


def test_rgb_image_round_trips() -> None:
    image = np.random.default_rng(0).integers(0, 255, (4, 6, 3), dtype=np.uint8)
    msg = image_msg(image, stamp(1.5), "cam_optical")
    assert (msg.height, msg.width, msg.encoding, msg.step) == (4, 6, "rgb8", 18)
    assert msg.header.frame_id == "cam_optical"
    assert np.array_equal(np.frombuffer(bytes(msg.data), np.uint8).reshape(4, 6, 3), image)


def test_depth_image_is_32fc1() -> None:
    depth = np.linspace(0.5, 2.0, 12, dtype=np.float32).reshape(3, 4)
    msg = image_msg(depth, stamp(0), "d")
    assert (msg.encoding, msg.step) == ("32FC1", 16)
    assert np.array_equal(np.frombuffer(bytes(msg.data), np.float32).reshape(3, 4), depth)


def test_image_of_another_layout_raises_naming_the_expected_ones() -> None:
    with pytest.raises(ValueError, match="HxWx3 uint8"):
        image_msg(np.zeros((4, 4, 4), np.uint8), stamp(0), "x")


def test_camera_info_is_the_pinhole_of_the_vertical_fov() -> None:
    msg = camera_info_msg(128, 96, 90.0, stamp(0), "cam")
    focal = 48.0  # (96 / 2) / tan(45 deg)
    assert msg.k[0] == pytest.approx(focal) and msg.k[4] == pytest.approx(focal)
    assert (msg.k[2], msg.k[5]) == (63.5, 47.5)
    assert list(msg.p) == [msg.k[0], 0, 63.5, 0, 0, msg.k[4], 47.5, 0, 0, 0, 1, 0]
    assert list(msg.d) == [0.0] * 5 and (msg.width, msg.height) == (128, 96)


def test_joint_state_keeps_order() -> None:
    msg = joint_state_msg(("a", "b"), np.array([1.0, 2.0]), np.zeros(2), np.ones(2), stamp(3))
    assert list(msg.name) == ["a", "b"] and list(msg.position) == [1.0, 2.0]
    assert list(msg.effort) == [1.0, 1.0] and msg.header.stamp.sec == 3


def test_laser_scan_spaces_beams_over_the_angle_range() -> None:
    ranges = np.array([1.0, np.inf, 2.0, 3.0, 4.0])
    msg = laser_scan_msg(
        ranges,
        angle_range_rad=(-1.0, 1.0),
        range_m=(0.1, 8.0),
        scan_time_s=0.1,
        stamp_msg=stamp(0),
        frame_id="laser",
    )
    assert msg.angle_increment == pytest.approx(0.5)
    assert msg.ranges[1] == math.inf and len(msg.ranges) == 5
    assert (msg.range_min, msg.range_max) == pytest.approx((0.1, 8.0))


def test_point_cloud_round_trips_xyz() -> None:
    points = np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]], np.float32)
    msg = point_cloud_msg(points, stamp(0), "base")
    assert (msg.width, msg.height, msg.point_step, msg.row_step) == (2, 1, 12, 24)
    assert [f.name for f in msg.fields] == ["x", "y", "z"] and msg.is_dense
    assert np.array_equal(np.frombuffer(bytes(msg.data), np.float32).reshape(2, 3), points)
    with pytest.raises(ValueError, match="N x 3"):
        point_cloud_msg(np.zeros((2, 2)), stamp(0), "base")
