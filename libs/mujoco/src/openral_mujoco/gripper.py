"""Gripper value conventions: how finger positions become a gripper value, and a gripper
command becomes an actuator control (and back, for the hold action).

Normalised values run from 0 (closed) to 1 (open); ``ctrl_range`` is (closed, open).
"""

from __future__ import annotations

from collections.abc import Sequence

from openral_core.models import GripperReadMode, GripperWriteMode


def read_gripper(
    mode: str, qpos: Sequence[float], ctrl_range: tuple[float, float], qpos_scale: float
) -> float:
    """Gripper value from the finger joint positions ``qpos`` (read at ``qpos_addrs``).

    - ``sum_over_scale``: sum of the finger positions over ``qpos_scale`` (parallel fingers).
    - ``affine_low_high``: ``(q - low) / (high - low)`` over ``ctrl_range`` (a revolute jaw
      whose closed position is not 0).
    - ``passthrough``: the first finger position verbatim (metres or radians).
    """
    if mode == GripperReadMode.sum_over_scale:
        return float(sum(qpos)) / qpos_scale
    if mode == GripperReadMode.affine_low_high:
        low, high = ctrl_range
        return (float(qpos[0]) - low) / (high - low)
    if mode == GripperReadMode.passthrough:
        return float(qpos[0])
    expected = [m.value for m in GripperReadMode]
    raise ValueError(f"unknown gripper read mode {mode!r}; expected one of {expected}")


def gripper_rate(
    mode: str, qvel: Sequence[float], ctrl_range: tuple[float, float], qpos_scale: float
) -> float:
    """Rate of change of :func:`read_gripper`'s value from the finger joint velocities (the
    same mapping without its offset: per second, in the read mode's units)."""
    if mode == GripperReadMode.affine_low_high:
        low, high = ctrl_range
        return float(qvel[0]) / (high - low)
    return read_gripper(mode, qvel, ctrl_range, qpos_scale)


def gripper_ctrl(mode: str, command: float, ctrl_range: tuple[float, float]) -> float:
    """Actuator control for a gripper command, before clipping to the actuator's ctrlrange.

    - ``normalised``: 0 → ``ctrl_range[0]`` (closed), 1 → ``ctrl_range[1]`` (open), clipped to
      [0, 1] first.
    - ``passthrough``: the command verbatim.
    """
    if mode == GripperWriteMode.normalised:
        low, high = ctrl_range
        return low + min(max(command, 0.0), 1.0) * (high - low)
    if mode == GripperWriteMode.passthrough:
        return command
    expected = [m.value for m in GripperWriteMode]
    raise ValueError(f"unknown gripper write mode {mode!r}; expected one of {expected}")


def gripper_command(mode: str, ctrl: float, ctrl_range: tuple[float, float]) -> float:
    """The command that gives actuator control ``ctrl`` (inverse of :func:`gripper_ctrl`):
    what holds a gripper where it is commanded now."""
    if mode == GripperWriteMode.normalised:
        low, high = ctrl_range
        return min(max((ctrl - low) / (high - low), 0.0), 1.0)
    return gripper_ctrl(mode, ctrl, ctrl_range)
