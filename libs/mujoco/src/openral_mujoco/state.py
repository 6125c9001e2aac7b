"""What a HAL reports: one joint-state sample in manifest joint order."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


class JointStateSample(NamedTuple):
    """Joint positions, velocities and efforts at one instant.

    Attributes:
        names: Canonical joint names, in manifest order.
        positions: rad or m; gripper joints carry the gripper value of their read mode.
        velocities: rad/s or m/s.
        efforts: N·m or N applied by each joint's actuator.
        stamp_ns: ``time.monotonic_ns()`` when the sample was taken.
        sim_time_s: Simulated time, or None for a real robot.
        stale: True when the source has not advanced for longer than the HAL's staleness
            limit (nobody is stepping the simulation, or the robot stopped reporting).
    """

    names: tuple[str, ...]
    positions: FloatArray
    velocities: FloatArray
    efforts: FloatArray
    stamp_ns: int
    sim_time_s: float | None = None
    stale: bool = False

    def as_dict(self) -> dict[str, float]:
        """Joint name → position."""
        return dict(zip(self.names, self.positions.tolist(), strict=True))
