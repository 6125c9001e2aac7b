"""A JointTrajectory taken raw is sized up from its CDR prefix before it is deserialised."""

from __future__ import annotations

import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from openral_bridge.joint_path import MAX_POINTS, PathRefused
from openral_nodes.trajectory_request import trajectory_msg
from openral_nodes.trajectory_wire import trajectory_from_wire
from rclpy.serialization import serialize_message
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

JOINTS = ("panda_joint1", "panda_joint4")
# A ROS string is UTF-8 and a C string: rosidl's serializer ends it at the first NUL, so text
# with a NUL or a lone surrogate cannot travel on the wire at all.
ROS_CHARS = st.characters(codec="utf-8", exclude_characters="\x00")


def _wire(msg: JointTrajectory) -> bytes:
    return bytes(serialize_message(msg))


@given(
    frame=st.text(ROS_CHARS, max_size=20),
    names=st.lists(st.text(ROS_CHARS, min_size=1, max_size=9), min_size=0, max_size=7),
    points=st.integers(0, 4),
)
@settings(max_examples=60, deadline=None)
def test_a_message_within_bounds_reads_back_whole(
    frame: str, names: list[str], points: int
) -> None:
    msg = JointTrajectory(joint_names=names)
    msg.header.frame_id = frame
    msg.points = [JointTrajectoryPoint(positions=[0.1 * i] * len(names)) for i in range(points)]
    back = trajectory_from_wire(_wire(msg), max_names=7)
    assert back.header.frame_id == frame
    assert list(back.joint_names) == names
    assert [list(p.positions) for p in back.points] == [list(p.positions) for p in msg.points]


def test_too_many_names_are_refused_before_deserialising() -> None:
    data = _wire(trajectory_msg(("panda_joint1",) * 100_000, [1.0], [[0.0] * 100_000]))
    started = time.perf_counter()
    with pytest.raises(PathRefused, match="names 100000 joints; the robot has 8"):
        trajectory_from_wire(data, max_names=8)
    print(f"refused in {1e3 * (time.perf_counter() - started):.3f} ms")


def test_too_many_points_are_refused_with_the_limit() -> None:
    msg = trajectory_msg(JOINTS, [0.001 * (i + 1) for i in range(MAX_POINTS + 1)],
                         [[0.0, 0.0]] * (MAX_POINTS + 1))  # fmt: skip
    with pytest.raises(PathRefused, match=f"{MAX_POINTS + 1} points; at most {MAX_POINTS}"):
        trajectory_from_wire(_wire(msg), max_names=8)


@pytest.mark.parametrize("cut", [0, 3, 10, 17, -1])
def test_truncated_or_foreign_bytes_are_refused(cut: int) -> None:
    data = _wire(trajectory_msg(JOINTS, [1.0], [[0.0, 0.0]]))
    with pytest.raises(PathRefused, match=r"ends early|not CDR|not a JointTrajectory"):
        trajectory_from_wire(data[:cut] if cut >= 0 else b"\x00\x07" + data[2:], max_names=8)


def test_a_claimed_count_larger_than_the_message_is_refused() -> None:
    data = bytearray(_wire(trajectory_msg(JOINTS, [1.0], [[0.0, 0.0]])))
    # 4 (encapsulation) + 8 (stamp) + 4 + 1 (empty frame_id) + 3 (padding) -> names count
    data[20:24] = (2**31).to_bytes(4, "little")
    with pytest.raises(PathRefused):
        trajectory_from_wire(bytes(data), max_names=2**32)
