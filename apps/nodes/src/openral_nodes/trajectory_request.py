"""``trajectory_msgs/JointTrajectory`` to and from openral's plain trajectory request.

:func:`request_from_msg` reads what the node receives (a header stamp of zero means "now";
any other is a start time in simulated time, the graph's ``/clock``); :func:`trajectory_msg`
builds one to send (what the rskill runner and ``openral ros`` examples do). Accelerations
and efforts in a point are not used: the control loop interpolates cubically (velocities
given) or linearly.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from builtin_interfaces.msg import Duration
from openral_bridge.joint_path import PathPoint, PathRefused, TrajectoryRequest
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

NS_PER_S = 1_000_000_000


def request_from_msg(msg: Any) -> TrajectoryRequest:
    """The request a received ``JointTrajectory`` makes.

    Raises:
        PathRefused: A ``time_from_start`` with nanoseconds outside [0, 1e9).
    """
    stamp = msg.header.stamp
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
    )


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
