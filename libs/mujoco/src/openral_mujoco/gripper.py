"""Gripper value conventions: how finger positions become a gripper value, and a gripper
command becomes an actuator control (and back, for the hold action).

Normalised values run from 0 (closed) to 1 (open); ``ctrl_range`` is (closed, open). Every
convention is affine, so each one is stated once here as an offset and weights
(:class:`Affine`); the functions below and the joint driver's precomputed maps apply them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from openral_core.models import GripperReadMode, GripperWriteMode


@dataclass(frozen=True)
class Affine:
    """``value = offset + Σ weights[k]·x[k]``; its rate is ``Σ weights[k]·ẋ[k]``."""

    offset: float
    weights: tuple[float, ...]

    def apply(self, x: Sequence[float]) -> float:
        """The mapped value of ``x`` (as many values as weights)."""
        return self.offset + sum(w * float(v) for w, v in zip(self.weights, x, strict=True))

    def rate(self, dx: Sequence[float]) -> float:
        """The mapped value's rate of change for rates ``dx`` (the offset drops out)."""
        return sum(w * float(v) for w, v in zip(self.weights, dx, strict=True))


def reading_map(
    mode: str, fingers: int, ctrl_range: tuple[float, float], qpos_scale: float
) -> Affine:
    """The gripper value as an affine map of its ``fingers`` finger joint positions.

    - ``sum_over_scale``: sum of the finger positions over ``qpos_scale`` (parallel fingers).
    - ``affine_low_high``: ``(q - low) / (high - low)`` over ``ctrl_range`` (a revolute jaw
      whose closed position is not 0), ``q`` the first finger.
    - ``passthrough``: the first finger position verbatim (metres or radians).
    """
    rest = (0.0,) * (fingers - 1)
    if mode == GripperReadMode.sum_over_scale:
        return Affine(0.0, (1.0 / qpos_scale,) * fingers)
    if mode == GripperReadMode.affine_low_high:
        low, high = ctrl_range
        return Affine(-low / (high - low), (1.0 / (high - low), *rest))
    if mode == GripperReadMode.passthrough:
        return Affine(0.0, (1.0, *rest))
    expected = [m.value for m in GripperReadMode]
    raise ValueError(f"unknown gripper read mode {mode!r}; expected one of {expected}")


def command_map(mode: str, ctrl_range: tuple[float, float]) -> Affine:
    """The actuator control as an affine map of a gripper command already inside its range
    (see :func:`command_range`).

    - ``normalised``: 0 → ``ctrl_range[0]`` (closed), 1 → ``ctrl_range[1]`` (open).
    - ``passthrough``: the command verbatim.
    """
    if mode == GripperWriteMode.normalised:
        low, high = ctrl_range
        return Affine(low, (high - low,))
    if mode == GripperWriteMode.passthrough:
        return Affine(0.0, (1.0,))
    expected = [m.value for m in GripperWriteMode]
    raise ValueError(f"unknown gripper write mode {mode!r}; expected one of {expected}")


def command_range(mode: str, ctrl_range: tuple[float, float]) -> tuple[float, float]:
    """The range a gripper command is clamped to: [0, 1] when ``normalised``, the ordered
    ``ctrl_range`` when ``passthrough``."""
    if mode == GripperWriteMode.normalised:
        return (0.0, 1.0)
    low, high = ctrl_range
    return (min(low, high), max(low, high))


def read_gripper(
    mode: str, qpos: Sequence[float], ctrl_range: tuple[float, float], qpos_scale: float
) -> float:
    """Gripper value from the finger joint positions ``qpos`` (see :func:`reading_map`)."""
    return reading_map(mode, len(qpos), ctrl_range, qpos_scale).apply(qpos)


def gripper_ctrl(mode: str, command: float, ctrl_range: tuple[float, float]) -> float:
    """Actuator control for a gripper command (clamped to :func:`command_range` first),
    before clipping to the actuator's ctrlrange."""
    low, high = command_range(mode, ctrl_range)
    return command_map(mode, ctrl_range).apply((min(max(command, low), high),))


def gripper_command(mode: str, ctrl: float, ctrl_range: tuple[float, float]) -> float:
    """The command that gives actuator control ``ctrl`` (inverse of :func:`gripper_ctrl`):
    what holds a gripper where it is commanded now."""
    forward = command_map(mode, ctrl_range)
    low, high = command_range(mode, ctrl_range)
    return min(max((ctrl - forward.offset) / forward.weights[0], low), high)


NORMALISED_READINGS = (GripperReadMode.sum_over_scale, GripperReadMode.affine_low_high)
"""Read modes that give a 0-1 opening (the others give the finger's own units)."""


@dataclass(frozen=True)
class SlotMap:
    """A gripper's action slot against its URDF joint: with every finger at ``q`` (metres or
    radians) the slot reads ``offset + gain * q``. A command in a write mode that shares the
    read mode's units is that same value."""

    offset: float
    gain: float

    def slot(self, joint: float) -> float:
        """The slot's value with every finger at ``joint``."""
        return self.offset + self.gain * joint

    def joint(self, slot: float) -> float:
        """The finger position a slot value stands for."""
        return (slot - self.offset) / self.gain


def slot_map(
    read_mode: str, fingers: int, ctrl_range: tuple[float, float], qpos_scale: float
) -> SlotMap:
    """The reading map (:func:`reading_map`) of ``fingers`` fingers moving together."""
    affine = reading_map(read_mode, fingers, ctrl_range, qpos_scale)
    return SlotMap(float(affine.offset), float(sum(affine.weights)))


def units_mismatch(read_mode: str, write_mode: str) -> str | None:
    """Why a gripper's commands cannot be given in its readings' units (None: they can):
    a normalised command with a reading in the finger's units, or the reverse."""
    normalised_in = read_mode in NORMALISED_READINGS
    if normalised_in == (write_mode == GripperWriteMode.normalised):
        return None
    return f"its read mode {read_mode} and write mode {write_mode} do not share units"
