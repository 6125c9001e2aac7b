"""Gripper read/write conventions (the arithmetic; real-model behaviour is in test_mujoco_arm)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from openral_mujoco.gripper import (
    command_range,
    gripper_command,
    gripper_ctrl,
    read_gripper,
    reading_map,
)

ranges = st.tuples(st.floats(-5, 5), st.floats(0.01, 5)).map(lambda t: (t[0], t[0] + t[1]))


def test_sum_over_scale_adds_the_fingers() -> None:
    assert read_gripper("sum_over_scale", [0.02, 0.02], (0.0, 255.0), 0.08) == pytest.approx(0.5)


def test_passthrough_reads_the_first_finger() -> None:
    assert read_gripper("passthrough", [0.031, -0.031], (0.021, 0.057), 1.0) == 0.031


@given(ctrl_range=ranges, command=st.floats(0, 1))
def test_normalised_write_then_affine_read_round_trips(
    ctrl_range: tuple[float, float], command: float
) -> None:
    ctrl = gripper_ctrl("normalised", command, ctrl_range)
    assert ctrl_range[0] <= ctrl <= ctrl_range[1]
    assert read_gripper("affine_low_high", [ctrl], ctrl_range, 1.0) == pytest.approx(
        command, abs=1e-9
    )


@given(ctrl_range=ranges, command=st.floats(-10, 10))
def test_normalised_commands_are_clipped_to_closed_and_open(
    ctrl_range: tuple[float, float], command: float
) -> None:
    ctrl = gripper_ctrl("normalised", command, ctrl_range)
    assert ctrl_range[0] <= ctrl <= ctrl_range[1]


def test_unknown_modes_are_refused() -> None:
    with pytest.raises(ValueError, match="read mode"):
        read_gripper("sideways", [0.0], (0.0, 1.0), 1.0)
    with pytest.raises(ValueError, match="write mode"):
        gripper_ctrl("sideways", 0.0, (0.0, 1.0))


@given(
    mode=st.sampled_from(["sum_over_scale", "affine_low_high", "passthrough"]),
    ctrl_range=ranges,
    fingers=st.lists(st.floats(-1, 1), min_size=1, max_size=4),
    rates=st.lists(st.floats(-1, 1), min_size=4, max_size=4),
)
def test_a_readings_rate_is_its_derivative(
    mode: str, ctrl_range: tuple[float, float], fingers: list[float], rates: list[float]
) -> None:
    reading = reading_map(mode, len(fingers), ctrl_range, 0.08)
    dx = rates[: len(fingers)]
    moved = [x + 1e-3 * v for x, v in zip(fingers, dx, strict=True)]
    change = (reading.apply(moved) - reading.apply(fingers)) / 1e-3
    assert change == pytest.approx(reading.rate(dx), rel=1e-6, abs=1e-6)
    assert reading.apply(fingers) == read_gripper(mode, fingers, ctrl_range, 0.08)


@given(mode=st.sampled_from(["normalised", "passthrough"]), ctrl_range=ranges, at=st.floats(0, 1))
def test_the_hold_command_gives_back_the_control(
    mode: str, ctrl_range: tuple[float, float], at: float
) -> None:
    low, high = command_range(mode, ctrl_range)
    command = low + at * (high - low)
    ctrl = gripper_ctrl(mode, command, ctrl_range)
    assert gripper_command(mode, ctrl, ctrl_range) == pytest.approx(command, abs=1e-9)
