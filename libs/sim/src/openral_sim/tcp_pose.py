"""The TCP's pose in the robot's base frame, as cheaply as it can be read.

It is in every env observation and every ``/openral/tcp_pose`` message. A native scene
composes a site at the TCP and two MuJoCo sensors of its pose in the robot's root body
(:mod:`openral_sim.tcp_sensors`). MuJoCo computes them with the rest of the state in C,
so a read is one copy of 7 values of ``sensordata``, composed with the root's pose in the
base frame when the root is not the base itself.

Without those sensors (a model composed otherwise) the reader composes the pose from rows
of ``data`` looked up once: world → base, the TCP's body or site, the flange.
"""

from __future__ import annotations

import mujoco
import numpy as np
from openral_mujoco.state import FloatArray

from openral_sim.end_effector import EndEffector
from openral_sim.frame_tree import FrameTree
from openral_sim.tcp_sensors import TCP_SENSORS

Pose = tuple[FloatArray, FloatArray]
"""A position [m] and a quaternion (w, x, y, z)."""

_IDENTITY = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))


def _sensed(model: mujoco.MjModel, root: int) -> int | None:
    """Where the TCP sensors' 7 values start in ``sensordata`` (None: no such sensors, or
    not in ``root``'s frame)."""
    found = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name) for name in TCP_SENSORS]
    if min(found) < 0:
        return None
    start = int(model.sensor_adr[found[0]])
    in_root = all(
        model.sensor_reftype[i] == mujoco.mjtObj.mjOBJ_XBODY and model.sensor_refid[i] == root
        for i in found
    )
    return start if in_root and model.sensor_adr[found[1]] == start + 3 else None


class TcpReader:
    """The TCP pose of one MjData in the base frame (see the module doc)."""

    def __init__(self, ee: EndEffector, frames: FrameTree, data: mujoco.MjData) -> None:
        self.ee, self.data = ee, data
        root = frames.tree.root
        self._root_in_base = frames.root_in_base
        self._root_is_base = all(
            np.array_equal(a, b) for a, b in zip(self._root_in_base, _IDENTITY, strict=True)
        )
        start = _sensed(data.model, root)
        self._sensors = None if start is None else data.sensordata[start : start + 7]
        """The TCP sensors' values (a view: it follows ``data``)."""
        self._root = (data.xpos[root], data.xquat[root])
        self._frame: Pose | None = (
            None if ee.kind == "site" else (data.xpos[ee.frame], data.xquat[ee.frame])
        )
        self._a, self._a_quat = np.empty(3), np.empty(4)

    def read(self) -> FloatArray:
        """The TCP's pose in the base frame: position [m], quaternion w, x, y, z, as of the
        last ``mj_forward`` (every native scene step ends with one; ``mj_kinematics`` alone
        leaves the sensors where they were)."""
        sensors = self._sensors
        if sensors is not None and self._root_is_base:
            return sensors.copy()
        out = np.empty(7)
        if sensors is not None:
            mujoco.mju_mulPose(out[:3], out[3:], *self._root_in_base, sensors[:3], sensors[3:])
            return out
        world_in_base = self._compose_world_in_base(*self._root)
        frame, frame_quat = self._frame or self.ee.frame_pose(self.data)
        a, a_quat = self._a, self._a_quat
        mujoco.mju_mulPose(a, a_quat, *world_in_base, frame, frame_quat)
        mujoco.mju_mulPose(out[:3], out[3:], a, a_quat, self.ee.offset, self.ee.flange_quat)
        return out

    def _compose_world_in_base(self, position: FloatArray, quat: FloatArray) -> Pose:
        """root-in-base · root⁻¹ for a root at world pose (``position``, ``quat``)."""
        inverse, inverse_quat = np.empty(3), np.empty(4)
        mujoco.mju_negPose(inverse, inverse_quat, position, quat)
        out, out_quat = np.empty(3), np.empty(4)
        mujoco.mju_mulPose(out, out_quat, *self._root_in_base, inverse, inverse_quat)
        return out, out_quat
