"""End-effector action modes: what an end-effector action means, in one place.

Both modes move the tool centre point (:mod:`openral_sim.end_effector`) in the robot's base
frame and set the first gripper; the arm's joint targets then come from the one IK, and the
whole joint action passes the manifest's limits and the E-stop like any other.

- ``ee_delta_pose``: 7 values in [-1, 1]: translation x, y, z, then a rotation as an axis
  times an angle (rx, ry, rz), both in the base frame and scaled by the preset's full scale
  per control step, then the gripper in the preset's sign. Presets: ``robosuite`` (its
  OSC_POSE: 0.05 m and 0.5 rad per step, -1 opens, +1 closes) and ``maniskill`` (its
  pd_ee_delta_pose: 0.1 m and 0.1 rad per step, -1 closes, +1 opens). The deltas add up in
  a reference pose that starts where the TCP is at reset and follows where the IK's step got
  when the limits stop it short, so a target out of reach does not wind up.
- ``ee_pose``: 8 values: the TCP's position [m] and orientation (w, x, y, z; normalised
  here) in the base frame, then the gripper in manifest units (0 closed, 1 open).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import mink
import mujoco
import numpy as np
from openral_mujoco.errors import ActionRejected
from openral_mujoco.state import FloatArray

from openral_sim.end_effector import EndEffector
from openral_sim.frame_tree import FrameTree
from openral_sim.tcp_pose import TcpReader

DELTA_WIDTH = 7
POSE_WIDTH = 8
_SMALLEST_QUAT = 1e-6
"""An ``ee_pose`` quaternion shorter than this has no direction to normalise to."""
_SNAP_M = 1e-3
"""A step that ends farther than this from the reference [m] moves the reference there."""


@dataclass(frozen=True)
class DeltaPreset:
    """The scale and gripper sign of one ``ee_delta_pose`` convention."""

    translation_m: float
    """Full-scale translation per control step [m]."""
    rotation_rad: float
    """Full-scale rotation per control step [rad]."""
    closes: float
    """The gripper value that closes it (+1 or -1)."""

    def gripper(self, value: float) -> float:
        """The normalised gripper command (0 closed, 1 open) of a value in [-1, 1]."""
        return (1.0 - value * self.closes) / 2.0


PRESETS = {
    "robosuite": DeltaPreset(translation_m=0.05, rotation_rad=0.5, closes=1.0),
    "maniskill": DeltaPreset(translation_m=0.1, rotation_rad=0.1, closes=-1.0),
}
"""The ``ee_delta_pose`` presets by name."""


def unit_quaternion(quat: FloatArray, name: str) -> FloatArray:
    """``quat`` (w, x, y, z) normalised; ``name`` says what it is in the error.

    Raises:
        ActionRejected: Its norm is (nearly) zero: no orientation to normalise to.
    """
    norm = float(np.linalg.norm(quat))
    if norm < _SMALLEST_QUAT:
        raise ActionRejected(
            f"{name} has norm {norm:g}; expected a rotation (it is normalised, but not from zero)"
        )
    unit: FloatArray = np.asarray(quat, dtype=np.float64) / norm
    return unit


class EeCommand:
    """Turns end-effector actions into arm joint targets and a gripper command."""

    def __init__(self, ee: EndEffector, frames: FrameTree, dt: float) -> None:
        self.ee, self.frames, self.dt = ee, frames, dt
        self.reference = mink.SE3.identity()
        """The TCP pose the deltas add up in (base frame)."""
        self._reader: TcpReader | None = None

    def base(self, data: mujoco.MjData) -> mink.SE3:
        """The base frame's pose in the world."""
        position, quat = self.frames.base_pose(data)
        return mink.SE3.from_rotation_and_translation(mink.SO3(quat), position)

    def tcp_vector(self, data: mujoco.MjData) -> FloatArray:
        """The TCP's pose in the base frame as 7 values: position [m], quaternion w, x, y, z
        (:class:`~openral_sim.tcp_pose.TcpReader`, bound to ``data`` once: it is in every
        observation)."""
        reader = self._reader
        if reader is None or reader.data is not data:
            reader = self._reader = TcpReader(self.ee, self.frames, data)
        return reader.read()

    def reach_box(
        self, model: mujoco.MjModel, data: mujoco.MjData
    ) -> tuple[FloatArray, FloatArray]:
        """The lowest and highest TCP position the arm can reach, in the base frame [m]: a
        box around its first joint as wide as the chain from joint to joint to the TCP is
        long in ``data``'s pose (the triangle inequality makes it an upper bound)."""
        arm_qpos = set(self.ee._arm_qpos.tolist())
        joints = [j for j in range(model.njnt) if int(model.jnt_qposadr[j]) in arm_qpos]
        points = [*(data.xanchor[j] for j in joints), self.ee.tcp.position(data)]
        reach = sum(float(np.linalg.norm(b - a)) for a, b in itertools.pairwise(points))
        centre = self.base(data).inverse().apply(points[0])
        return centre - reach, centre + reach

    def reset(self, data: mujoco.MjData, commanded: FloatArray) -> None:
        """Start the reference where the arm's ``commanded`` targets put the TCP (where
        the servos are taking it, not where gravity holds it a little below)."""
        world = self.ee.commanded_pose(data, commanded)
        self.reference = self.base(data).inverse().multiply(world)

    def delta(
        self, data: mujoco.MjData, commanded: FloatArray, action: FloatArray, preset: DeltaPreset
    ) -> tuple[FloatArray, float]:
        """(arm joint targets, gripper command) of one ``ee_delta_pose`` action."""
        translation = self.reference.translation() + action[:3] * preset.translation_m
        turn = mink.SO3.exp(action[3:6] * preset.rotation_rad)
        rotation = turn.multiply(self.reference.rotation())
        self.reference = mink.SE3.from_rotation_and_translation(rotation, translation)
        return self._solve(data, commanded), preset.gripper(float(action[6]))

    def absolute(
        self, data: mujoco.MjData, commanded: FloatArray, action: FloatArray
    ) -> tuple[FloatArray, float]:
        """(arm joint targets, gripper command) of one ``ee_pose`` action.

        Raises:
            ActionRejected: The quaternion is (nearly) zero: no orientation at all.
        """
        quat = unit_quaternion(action[3:7], "ee_pose quaternion (qw, qx, qy, qz)")
        self.reference = mink.SE3.from_rotation_and_translation(mink.SO3(quat), action[:3])
        return self._solve(data, commanded), float(action[7])

    def _solve(self, data: mujoco.MjData, commanded: FloatArray) -> FloatArray:
        """One IK step towards the reference; where the limits stopped it short, the
        reference comes back to where the step got (no wind-up at the workspace edge)."""
        base = self.base(data)
        targets = self.ee.joint_targets(data, commanded, base.multiply(self.reference), self.dt)
        if self.ee.shortfall_m > _SNAP_M:
            self.reference = base.inverse().multiply(self.ee.commanded_pose(data, targets))
        return targets
