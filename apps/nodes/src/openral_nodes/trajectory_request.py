"""``trajectory_msgs/JointTrajectory`` and FollowJointTrajectory goals to and from openral's
plain trajectory request.

:func:`request_from_msg` reads what the node receives (a header stamp of zero means "now";
any other is a start time in simulated time, the graph's ``/clock``); :func:`goal_request`
reads a FollowJointTrajectory goal (its trajectory, and its tolerances resolved against the
robot's defaults as joint_trajectory_controller resolves them: 0 keeps the default, -1
erases it, any other negative value is refused); :func:`trajectory_msg` builds a message to
send. Accelerations and efforts in a point are not used: the control loop interpolates
cubically (velocities given) or linearly. Every check is linear in the message's size, and a
message with more than :data:`~openral_bridge.joint_path.MAX_POINTS` points is refused before
any of its points is read.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration
from openral_bridge.joint_path import MAX_POINTS, PathPoint, PathRefused, TrajectoryRequest
from openral_bridge.trajectory_goal import Tolerances
from openral_core.models import TrajectoryRules
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

NS_PER_S = 1_000_000_000
ERASE = -1.0
"""A goal tolerance of this value erases the default (no check)."""
GOAL_SOURCE = "a FollowJointTrajectory goal"


def request_from_msg(msg: Any, source: str = "a joint trajectory") -> TrajectoryRequest:
    """The request a received ``JointTrajectory`` makes.

    Raises:
        PathRefused: More than :data:`MAX_POINTS` points, a ``time_from_start`` with
            nanoseconds outside [0, 1e9), or a header stamp with them.
    """
    if len(msg.points) > MAX_POINTS:
        raise PathRefused(f"the trajectory has {len(msg.points)} points; at most {MAX_POINTS}")
    stamp = msg.header.stamp
    if not 0 <= int(stamp.nanosec) < NS_PER_S:
        raise PathRefused(f"header.stamp.nanosec is {stamp.nanosec}; expected 0 to 999999999")
    start_ns = int(stamp.sec) * NS_PER_S + int(stamp.nanosec)
    points = []
    for k, point in enumerate(msg.points):
        duration = point.time_from_start
        if not 0 <= int(duration.nanosec) < NS_PER_S:
            raise PathRefused(
                f"points[{k}].time_from_start.nanosec is {duration.nanosec}; "
                "expected 0 to 999999999"
            )
        seconds = int(duration.sec) + int(duration.nanosec) / NS_PER_S
        points.append(
            PathPoint(
                seconds,
                tuple(float(v) for v in point.positions),
                tuple(float(v) for v in point.velocities),
            )
        )
    return TrajectoryRequest(
        joint_names=tuple(str(n) for n in msg.joint_names),
        points=tuple(points),
        start_s=None if start_ns == 0 else start_ns / NS_PER_S,
        source=source,
    )


def goal_request(goal: Any, rules: TrajectoryRules) -> tuple[TrajectoryRequest, Tolerances]:
    """The request and the tolerances of a FollowJointTrajectory goal.

    Raises:
        PathRefused: A multi-DOF trajectory, a tolerance naming a joint the trajectory does
            not move, a NaN or negative (but -1) tolerance, or a bad trajectory.
    """
    multi = goal.multi_dof_trajectory
    if len(multi.joint_names) or len(multi.points):
        raise PathRefused("multi_dof_trajectory: multi-DOF joints are not followed here")
    request = request_from_msg(goal.trajectory, GOAL_SOURCE)
    names = request.joint_names
    path_pos, path_vel = _tolerances(goal.path_tolerance, names, "path_tolerance", 0.0, 0.0)
    goal_pos, goal_vel = _tolerances(
        goal.goal_tolerance, names, "goal_tolerance", 0.0, rules.stopped_velocity_tolerance
    )
    duration = goal.goal_time_tolerance
    seconds = int(duration.sec) + int(duration.nanosec) / NS_PER_S
    goal_time = _resolved(seconds, rules.goal_time_s, "goal_time_tolerance")
    return request, Tolerances(path_pos, path_vel, goal_pos, goal_vel, goal_time)


def _tolerances(
    given: Sequence[Any], names: tuple[str, ...], field: str, position: float, velocity: float
) -> tuple[Any, Any]:
    """(positions, velocities) per joint of ``names``: the defaults, overridden by ``given``."""
    index = {name: i for i, name in enumerate(names)}
    positions, velocities = np.full(len(names), position), np.full(len(names), velocity)
    for k, tolerance in enumerate(given):
        where = f"{field}[{k}]"
        if tolerance.name not in index:
            shown = str(tolerance.name)[:80]
            raise PathRefused(f"{where}.name {shown!r} is not a joint of the trajectory")
        i = index[tolerance.name]
        positions[i] = _resolved(float(tolerance.position), position, f"{where}.position")
        velocities[i] = _resolved(float(tolerance.velocity), velocity, f"{where}.velocity")
    return positions, velocities


def _resolved(value: float, default: float, where: str) -> float:
    """A goal's tolerance against the default: > 0 replaces it, 0 keeps it, -1 erases it."""
    if not math.isfinite(value) or (value < 0.0 and value != ERASE):
        raise PathRefused(f"{where} is {value}; expected > 0, 0 (the default) or -1 (none)")
    if value > 0.0:
        return value
    return 0.0 if value == ERASE else default


def trajectory_msg(
    joint_names: Sequence[str],
    times_s: Sequence[float],
    positions: Sequence[Sequence[float]],
    velocities: Sequence[Sequence[float]] | None = None,
) -> Any:
    """A ``JointTrajectory`` starting now (header stamp zero): one point per time [s], with
    its positions (and velocities, when given) in the order of ``joint_names``."""
    msg = JointTrajectory(joint_names=list(joint_names))
    for k, time_s in enumerate(times_s):
        nanoseconds = round(time_s * NS_PER_S)
        point = JointTrajectoryPoint(
            positions=[float(v) for v in positions[k]],
            time_from_start=Duration(sec=nanoseconds // NS_PER_S, nanosec=nanoseconds % NS_PER_S),
        )
        if velocities is not None:
            point.velocities = [float(v) for v in velocities[k]]
        msg.points.append(point)
    return msg
