"""A ``trajectory_msgs/JointTrajectory`` read from its serialised bytes, sized up first.

Deserialising a message builds a Python object for every joint name and point while holding
the GIL: a trajectory naming one joint 1e5 times takes ~35 ms to turn into objects and
validate, time in which the E-stop thread cannot run. The topic is therefore taken raw and
its CDR prefix is read first (header, ``joint_names``, the count of ``points``): a message
with more names than the robot has joints, more than
:data:`~openral_bridge.joint_path.MAX_POINTS` points, or a malformed prefix is refused
before any object is made, so the cost of a refusal is bounded by the names it reads.
"""

from __future__ import annotations

import struct
from typing import Any

from openral_bridge.joint_path import MAX_POINTS, PathRefused
from rclpy.serialization import deserialize_message
from trajectory_msgs.msg import JointTrajectory

_ENCAPSULATION = {0: ">", 1: "<"}  # CDR_BE, CDR_LE (the second byte of the header)


class _Reader:
    """Reads CDR fields from ``data`` after its 4-byte encapsulation header."""

    def __init__(self, data: bytes) -> None:
        if len(data) < 4 or data[1] not in _ENCAPSULATION:
            raise PathRefused("the message is not CDR-encoded")
        self.data, self.at, self.order = data, 4, _ENCAPSULATION[data[1]]

    def uint32(self) -> int:
        self.at += -(self.at - 4) % 4  # align to 4 from the start of the payload
        if self.at + 4 > len(self.data):
            raise PathRefused("the message ends early")
        (value,) = struct.unpack_from(self.order + "I", self.data, self.at)
        self.at += 4
        return int(value)

    def skip_string(self) -> None:
        size = self.uint32()
        if self.at + size > len(self.data):
            raise PathRefused("the message ends early")
        self.at += size


def _points(reader: _Reader, names: int) -> int:
    for _ in range(names):
        reader.skip_string()
    return reader.uint32()


def trajectory_from_wire(data: bytes, max_names: int) -> Any:
    """The JointTrajectory in ``data``, once its size is within bounds.

    Args:
        data: The serialised message (a raw subscription's bytes).
        max_names: The most joint names a trajectory of this robot can carry (its joints).

    Raises:
        PathRefused: More names than ``max_names``, more than :data:`MAX_POINTS` points, or
            bytes that are not a JointTrajectory.
    """
    reader = _Reader(data)
    for _ in range(2):
        reader.uint32()
    reader.skip_string()
    names = reader.uint32()
    if names > max_names:
        raise PathRefused(f"the trajectory names {names} joints; the robot has {max_names}")
    points = _points(reader, names)
    if points > MAX_POINTS:
        raise PathRefused(f"the trajectory has {points} points; at most {MAX_POINTS}")
    try:
        return deserialize_message(data, JointTrajectory)
    except Exception as error:  # rclpy raises a bare error on malformed CDR
        raise PathRefused(f"the message is not a JointTrajectory ({error})") from None
