"""Tests for motion_envelope.py: the safety envelope of a real arm's goals, as properties."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from openral_real.motion_envelope import MotionEnvelope

LOW = np.array([-1.9, -1.7, 0.0])
HIGH = np.array([1.9, 1.7, 1.7])
SPEED = np.array([10.0, 2.0, 5.0])
PERIOD = 0.01

angles = st.lists(st.floats(-5, 5), min_size=3, max_size=3).map(np.array)


def _envelope(scale: float = 0.2) -> MotionEnvelope:
    return MotionEnvelope(LOW, HIGH, SPEED, PERIOD, scale)


@settings(max_examples=200, deadline=None)
@given(start=angles, commands=st.lists(angles, min_size=1, max_size=8), steps=st.integers(1, 60))
def test_no_goal_is_faster_than_the_limit_or_outside_the_limits_once_inside(
    start: np.ndarray, commands: list[np.ndarray], steps: int
) -> None:
    envelope = _envelope(scale=1.0)
    measured = np.clip(start, LOW, HIGH)
    envelope.start(measured)
    goal = measured
    for command in commands:
        envelope.aim(command)
        assert np.all(envelope.target >= LOW) and np.all(envelope.target <= HIGH)
        for _ in range(steps):
            new = envelope.step()
            assert np.all(np.abs(new - goal) <= SPEED * PERIOD + 1e-12)
            assert np.all(new >= LOW - 1e-12) and np.all(new <= HIGH + 1e-12)
            goal = new


@settings(max_examples=100, deadline=None)
@given(start=angles, command=angles)
def test_the_first_goal_is_where_the_arm_is_and_the_first_motion_slow(
    start: np.ndarray, command: np.ndarray
) -> None:
    envelope = _envelope(scale=0.2)
    measured = np.clip(start, LOW, HIGH)
    envelope.start(measured)
    assert np.array_equal(envelope.goal, measured)  # held where measured: no jump
    envelope.aim(command)
    first = envelope.step()
    assert np.all(np.abs(first - measured) <= 0.2 * SPEED * PERIOD + 1e-12)


def test_the_first_motion_ends_when_the_goal_catches_up() -> None:
    envelope = _envelope(scale=0.1)
    envelope.start(np.zeros(3))
    envelope.aim(np.array([0.01, 0.0, 0.0]))
    while envelope.first_motion:
        envelope.step()
    envelope.aim(np.array([1.0, 0.0, 0.0]))
    before = envelope.goal
    assert envelope.step()[0] - before[0] == SPEED[0] * PERIOD  # the whole limit now


def test_clamped_commands_are_counted_per_joint() -> None:
    envelope = _envelope()
    envelope.start(np.zeros(3))
    envelope.aim(np.array([0.0, 3.0, -1.0]))
    assert envelope.clamped.tolist() == [0, 1, 1]
    assert envelope.target.tolist() == [0.0, 1.7, 0.0]
