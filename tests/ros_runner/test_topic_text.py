"""Image decoding and message rendering used by ``openral ros`` and the runner."""

from __future__ import annotations

import numpy as np
import pytest
from openral_bridge.ros_messages import image_msg, stamp
from openral_nodes.topic_codec import ImageEncodingError, image_to_rgb
from openral_nodes.topic_format import format_message
from openral_nodes.topic_graph import MessageTypeError, is_hidden, message_class
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

RGB = np.arange(3 * 4 * 3, dtype=np.uint8).reshape(3, 4, 3)


def test_rgb8_round_trips_through_the_bridge_packer() -> None:
    assert np.array_equal(image_to_rgb(image_msg(RGB, stamp(0.0), "cam")), RGB)


def test_bgr8_with_row_padding_is_flipped_and_unpadded() -> None:
    msg = Image(height=3, width=4, encoding="bgr8", step=16)
    rows = np.zeros((3, 16), np.uint8)
    rows[:, :12] = RGB[:, :, ::-1].reshape(3, 12)
    rows[:, 12:] = 255  # padding must not leak into pixels
    msg.data = rows.tobytes()
    assert np.array_equal(image_to_rgb(msg), RGB)


def test_mono8_becomes_grey_rgb() -> None:
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4)
    msg = Image(height=3, width=4, encoding="mono8", step=4, data=grey.tobytes())
    assert np.array_equal(image_to_rgb(msg), np.repeat(grey[:, :, None], 3, axis=2))


@pytest.mark.parametrize(
    ("encoding", "step", "size", "message"),
    [
        ("32FC1", 16, 48, "encoding '32FC1' is not supported; expected one of rgb8, bgr8, mono8"),
        ("rgb8", 12, 20, r"malformed rgb8 image: 4x3, step 12, 20 data bytes"),
        ("rgb8", 8, 36, "need step >= 12"),
    ],
)
def test_unusable_images_raise_a_clear_error(
    encoding: str, step: int, size: int, message: str
) -> None:
    msg = Image(height=3, width=4, encoding=encoding, step=step, data=bytes(size))
    with pytest.raises(ImageEncodingError, match=message):
        image_to_rgb(msg)


def test_messages_render_as_nested_fields_with_big_arrays_summarised() -> None:
    text = format_message(image_msg(np.full((20, 30, 3), 7, np.uint8), stamp(1.5), "wrist"))
    assert "header:\n  stamp:\n    sec: 1\n    nanosec: 500000000\n  frame_id: wrist" in text
    assert "encoding: rgb8" in text
    assert "data: <1800 values uint8: min 7, max 7, mean 7.0>" in text


def test_short_sequences_print_inline_and_message_lists_as_items() -> None:
    joints = format_message(JointState(name=["a", "b"], position=[0.5, 2.0]))
    assert "name: [a, b]\nposition: [0.5, 2.0]\nvelocity: []" in joints
    array = Float64MultiArray(data=[1.0, -2.5])
    array.layout.dim = [MultiArrayDimension(label="x", size=2, stride=2)]
    assert format_message(array) == (
        "layout:\n  dim:\n  - label: x\n    size: 2\n    stride: 2\n  data_offset: 0\n"
        "data: [1.0, -2.5]"
    )


def test_message_types_resolve_from_graph_names() -> None:
    assert message_class("sensor_msgs/msg/JointState", "/j") is JointState
    with pytest.raises(MessageTypeError, match="not a message type"):
        message_class("std_srvs/srv/Trigger", "/t")
    with pytest.raises(MessageTypeError, match="nope_msgs/msg/Thing, which openral does not"):
        message_class("nope_msgs/msg/Thing", "/n")


def test_a_peers_control_characters_are_shown_escaped_never_sent_to_the_terminal() -> None:
    from openral_nodes.topic_format import format_value

    hostile = "ok\x1b[2J\x07"  # clear screen and bell
    assert format_value(hostile) == "ok\\x1b[2J\\x07"
    assert format_value("sensor_msgs/msg/Image") == "sensor_msgs/msg/Image"


@pytest.mark.parametrize(
    ("name", "hidden"),
    [
        ("/rosout", True),
        ("/parameter_events", True),
        ("/openral/joint_trajectory_controller/follow_joint_trajectory/_action/feedback", True),
        ("/a/_b", True),
        ("/joint_states", False),
        ("/openral/joint_trajectory/state", False),
        ("/rosout_agg", False),
    ],
)
def test_hidden_topics_are_the_ones_ros2_topic_list_hides(name: str, hidden: bool) -> None:
    assert is_hidden(name) is hidden
