"""CameraMessages: one camera's Image and CameraInfo, reused frame after frame."""

from __future__ import annotations

import math

import numpy as np
import pytest
from openral_bridge.camera_messages import CameraMessages
from openral_bridge.ros_messages import camera_info_msg, image_msg, stamp


def test_a_frame_drawn_into_pixels_is_the_image_that_image_msg_would_build() -> None:
    messages = CameraMessages("cam_optical", 60.0)
    pixels = messages.pixels(4, 6)
    pixels[...] = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    messages.fill(pixels)  # drawn in place: nothing to copy
    image, info = messages.stamped(stamp(1.5))
    expected = image_msg(pixels.copy(), stamp(1.5), "cam_optical")
    assert image == expected
    assert info == camera_info_msg(6, 4, 60.0, stamp(1.5), "cam_optical")


def test_the_same_buffer_serves_every_frame_of_one_size() -> None:
    messages = CameraMessages("c", None)
    first = messages.pixels(8, 8)
    messages.fill(np.full((8, 8, 3), 3, np.uint8))
    image, info = messages.stamped(stamp(2.0))
    assert info is None and set(bytes(image.data)) == {3}
    assert messages.pixels(8, 8) is first
    messages.fill(np.full((8, 8, 3), 9, np.uint8))
    again, _ = messages.stamped(stamp(2.05))
    assert again is image and set(bytes(again.data)) == {9}
    assert again.header.stamp.nanosec == 50_000_000


def test_a_new_size_gets_new_messages() -> None:
    messages = CameraMessages("c", 90.0)
    messages.fill(np.zeros((4, 4, 3), np.uint8))
    small, small_info = messages.stamped(stamp(0.0))
    messages.fill(np.zeros((6, 10, 3), np.uint8))
    large, large_info = messages.stamped(stamp(0.0))
    assert large is not small and (large.height, large.width, large.step) == (6, 10, 30)
    assert large_info is not None and small_info is not None
    assert large_info.k[0] == pytest.approx(3.0 / math.tan(math.radians(45.0)))


def test_a_frame_that_is_not_rgb8_and_a_publish_before_any_frame_are_refused() -> None:
    messages = CameraMessages("c", None)
    with pytest.raises(RuntimeError, match="no frame yet"):
        messages.stamped(stamp(0.0))
    with pytest.raises(ValueError, match="rgb8"):
        messages.fill(np.zeros((4, 4), np.float32))
