"""Gripper value conventions: how a qpos reading becomes a gripper value and back.

Normalised values run from 0 (closed) to 1 (open); ``ctrl_range`` is (closed, open).
"""

from __future__ import annotations

from collections.abc import Sequence

READ_MODES = ("sum_over_scale", "affine_low_high", "passthrough")
WRITE_MODES = ("normalised", "passthrough")


def read_gripper(
    mode: str, qpos: Sequence[float], ctrl_range: tuple[float, float], qpos_scale: float
) -> float:
    """Gripper value from the finger joint positions ``qpos`` (read at ``qpos_addrs``).

    - ``sum_over_scale``: sum of the finger positions over ``qpos_scale`` (parallel fingers).
    - ``affine_low_high``: ``(q - low) / (high - low)`` over ``ctrl_range`` (a revolute jaw
      whose closed position is not 0).
    - ``passthrough``: the first finger position verbatim (metres or radians).
    """
    if mode == "sum_over_scale":
        return float(sum(qpos)) / qpos_scale
    if mode == "affine_low_high":
        low, high = ctrl_range
        return (float(qpos[0]) - low) / (high - low)
    if mode == "passthrough":
        return float(qpos[0])
    raise ValueError(f"unknown gripper read mode {mode!r}; expected one of {READ_MODES}")


def gripper_ctrl(mode: str, command: float, ctrl_range: tuple[float, float]) -> float:
    """Actuator control for a gripper command, before clipping to the actuator's ctrlrange.

    - ``normalised``: 0 → ``ctrl_range[0]`` (closed), 1 → ``ctrl_range[1]`` (open), clipped to
      [0, 1] first.
    - ``passthrough``: the command verbatim.
    """
    if mode == "normalised":
        low, high = ctrl_range
        return low + min(max(command, 0.0), 1.0) * (high - low)
    if mode == "passthrough":
        return command
    raise ValueError(f"unknown gripper write mode {mode!r}; expected one of {WRITE_MODES}")
