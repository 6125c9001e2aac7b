"""The manifest's command envelope: each action slot's allowed range, clamped and reported.

An arm joint's target is clamped to its ``position_limits`` (a continuous joint has none);
a ``normalised`` gripper command to [0, 1]; a ``passthrough`` gripper command to its
``ctrl_range``. Every clamp is counted per joint, and logged as a warning naming the joint,
the value and the limits at most once per :data:`WARN_EVERY_S` per joint.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence

import numpy as np
from openral_core.models import LimitedJoint, RobotDescription
from openral_core.tables import GripperWiring

from openral_mujoco.gripper import command_range
from openral_mujoco.state import FloatArray

WARN_EVERY_S = 2.0
"""Shortest interval between two clamp warnings of one joint [s]."""

_log = logging.getLogger(__name__)


class CommandLimits:
    """Per-slot [low, high] of one robot's action, with clamp counters."""

    def __init__(self, robot: RobotDescription, grippers: Sequence[GripperWiring]) -> None:
        """Ranges of every manifest joint, in manifest order."""
        by_joint = {g.joint: g for g in grippers}
        self.names = tuple(j.name for j in robot.joints)
        ranges = [
            command_range(by_joint[j.name].write_mode, by_joint[j.name].ctrl_range)
            if j.name in by_joint
            else (j.position_limits if isinstance(j, LimitedJoint) else [-np.inf, np.inf])
            for j in robot.joints
        ]
        self.low = np.array([r[0] for r in ranges], dtype=np.float64)
        self.high = np.array([r[1] for r in ranges], dtype=np.float64)
        self._low, self._high = self.low.tolist(), self.high.tolist()
        self.clamped = dict.fromkeys(self.names, 0)
        """Joint → how many commands were clamped onto its limits so far."""
        self._warned_ns = dict.fromkeys(self.names, -(1 << 62))

    def outside(self, values: FloatArray) -> tuple[int, ...]:
        """Indices of the values outside their limits (a control loop asks only when its own
        one-pass clamp changed something)."""
        bounds = zip(values.tolist(), self._low, self._high, strict=True)
        return tuple(i for i, (v, low, high) in enumerate(bounds) if v < low or v > high)

    def report(self, indices: tuple[int, ...], values: FloatArray) -> None:
        """Count the clamp of each of ``values[indices]``; log it at most once per
        :data:`WARN_EVERY_S` per joint."""
        now = time.monotonic_ns()
        for index in indices:
            self._report(index, float(values[index]), now)

    def _report(self, index: int, value: float, now_ns: int) -> None:
        name = self.names[index]
        self.clamped[name] += 1
        if now_ns - self._warned_ns[name] < WARN_EVERY_S * 1e9:
            return
        self._warned_ns[name] = now_ns
        _log.warning(
            "%s: command %.6g is outside its limits [%.6g, %.6g]; clamped (%d so far)",
            name,
            value,
            self.low[index],
            self.high[index],
            self.clamped[name],
        )
