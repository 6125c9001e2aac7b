"""A trajectory goal judged against its path once per control tick, as ros2_control's
joint_trajectory_controller judges a FollowJointTrajectory goal.

Each tick compares where the path wants the goal's joints (the path at the tick's simulated
time: its first knot before it starts, its last point at rest after it ends) with where the
joints are measured:

- while the path runs (between its start and its last point), a joint whose position or
  velocity error exceeds its **path tolerance** aborts the goal (PATH_TOLERANCE_VIOLATED);
- from the last point's time on, the goal **succeeds** on the first tick at which every joint
  is within its **goal tolerance** (position, and velocity: a joint must also have stopped);
  if that has not happened ``goal_time_s`` after the last point, the goal is aborted
  (GOAL_TOLERANCE_VIOLATED); with ``goal_time_s`` 0 it waits without limit.

A tolerance of 0 is not checked (the controller's convention; a goal's ``-1`` erases a
default and arrives here as 0).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np
from openral_mujoco.state import FloatArray

from openral_bridge.joint_path import JointPath

SAME_TIME_S = 1e-9
"""Times closer than this are the same instant [s]."""


class Outcome(StrEnum):
    """Where a goal stands after a tick."""

    RUNNING = "running"
    SUCCEEDED = "succeeded"
    PATH_TOLERANCE_VIOLATED = "path_tolerance_violated"
    GOAL_TOLERANCE_VIOLATED = "goal_tolerance_violated"


@dataclass(frozen=True)
class Tolerances:
    """Per joint of the goal (in its ``joint_names`` order): 0 means not checked."""

    path_position: FloatArray
    path_velocity: FloatArray
    goal_position: FloatArray
    goal_velocity: FloatArray
    goal_time_s: float
    """How long after the last point the goal tolerance may take to be met [s]; 0: no limit."""


@dataclass(frozen=True)
class Progress:
    """One tick of a goal: desired and measured state of its joints, and the verdict."""

    time_s: float
    desired_positions: FloatArray
    desired_velocities: FloatArray
    actual_positions: FloatArray
    actual_velocities: FloatArray
    outcome: Outcome
    message: str = ""

    @property
    def error_positions(self) -> FloatArray:
        """Desired minus measured positions (the controller's sign)."""
        error: FloatArray = self.desired_positions - self.actual_positions
        return error

    @property
    def error_velocities(self) -> FloatArray:
        """Desired minus measured velocities."""
        error: FloatArray = self.desired_velocities - self.actual_velocities
        return error


def judge(
    path: JointPath,
    tolerances: Tolerances,
    positions: FloatArray,
    velocities: FloatArray,
    now_s: float,
) -> Progress:
    """The goal of ``path`` at simulated time ``now_s``, its joints measured at ``positions``
    and ``velocities`` (one value per action slot, all slots).

    Args:
        path: The goal's path.
        tolerances: The goal's tolerances.
        positions: Measured positions of every action slot.
        velocities: Measured velocities of every action slot.
        now_s: The tick's simulated time [s].
    """
    desired, speed = path.sample(now_s)
    actual, moving = positions[path.slots], velocities[path.slots]
    progress = Progress(now_s, desired, speed, actual, moving, Outcome.RUNNING)
    ended = now_s >= path.end_s - SAME_TIME_S
    if not ended:
        if now_s > path.start_s + SAME_TIME_S:
            return _path_check(path, tolerances, progress)
        return progress
    far = _outside(progress, tolerances.goal_position, tolerances.goal_velocity)
    if far is None:
        return _with(progress, Outcome.SUCCEEDED, "goal reached")
    late_s = now_s - path.end_s
    if tolerances.goal_time_s > 0.0 and late_s > tolerances.goal_time_s + SAME_TIME_S:
        joint, what = far
        message = (
            f"{path.names[joint]} {what} {tolerances.goal_time_s:g} s after the trajectory's "
            "last point (goal_time_tolerance)"
        )
        return _with(progress, Outcome.GOAL_TOLERANCE_VIOLATED, message)
    return progress


def _path_check(path: JointPath, tolerances: Tolerances, progress: Progress) -> Progress:
    far = _outside(progress, tolerances.path_position, tolerances.path_velocity)
    if far is None:
        return progress
    joint, what = far
    message = f"{path.names[joint]} {what} at t={progress.time_s:.3f} s (path_tolerance)"
    return _with(progress, Outcome.PATH_TOLERANCE_VIOLATED, message)


def _outside(
    progress: Progress, position: FloatArray, velocity: FloatArray
) -> tuple[int, str] | None:
    """(joint, what is off) of the first joint outside the tolerances, else None."""
    checks = (
        ("is", progress.error_positions, position, "from its desired position"),
        ("moves", progress.error_velocities, velocity, "away from its desired velocity"),
    )
    for verb, error, tolerance, where in checks:
        over = np.flatnonzero((tolerance > 0.0) & (np.abs(error) > tolerance))
        if over.size:
            i = int(over[0])
            return i, f"{verb} {abs(float(error[i])):.4g} {where} (tolerance {tolerance[i]:g})"
    return None


def _with(progress: Progress, outcome: Outcome, message: str) -> Progress:
    return replace(progress, outcome=outcome, message=message)
