"""A FollowJointTrajectory client of a live graph, as MoveIt's controller handle is one: send
a goal, collect its feedback, cancel it, read its result."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import Any

from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from control_msgs.msg import JointTolerance
from openral_bridge.topics import FOLLOW_JOINT_TRAJECTORY
from openral_nodes.trajectory_action import FEEDBACK_DEPTH
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import QoSProfile
from trajectory_msgs.msg import JointTrajectoryPoint

from tests.ros.ros_helpers import wait_until

PANDA_ARM = tuple(f"panda_joint{i}" for i in range(1, 8))


def duration(seconds: float) -> Any:
    """A builtin_interfaces/Duration of ``seconds`` (>= 0)."""
    nanoseconds = round(seconds * 1e9)
    return Duration(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def goal(
    names: tuple[str, ...],
    points: list[tuple[float, list[float]]],
    *,
    goal_tolerance: float = 0.0,
    goal_time_s: float = 0.0,
    path_tolerance: float = 0.0,
) -> Any:
    """A goal through ``points`` ((time [s], positions)), at rest at each point."""
    message = FollowJointTrajectory.Goal()
    message.trajectory.joint_names = list(names)
    for time_s, positions in points:
        message.trajectory.points.append(
            JointTrajectoryPoint(
                positions=[float(v) for v in positions],
                velocities=[0.0] * len(names),
                time_from_start=duration(time_s),
            )
        )
    if goal_tolerance:
        message.goal_tolerance = [JointTolerance(name=n, position=goal_tolerance) for n in names]
    if path_tolerance:
        message.path_tolerance = [JointTolerance(name=n, position=path_tolerance) for n in names]
    message.goal_time_tolerance = duration(goal_time_s)
    return message


class _AtomicActionClient(ActionClient):  # type: ignore[misc]
    """An ActionClient whose requests register before their response can be taken.

    rclpy (Jazzy) sends a goal, cancel or result request and only then records its sequence
    number; a response taken on the spin thread in between is dropped ("Ignoring unexpected
    cancel response") and its future never completes (ros2/rclpy#1123). One lock around the
    send-and-register and around the handling of a response closes that window.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._register = threading.RLock()

    def send_goal_async(self, *args: Any, **kwargs: Any) -> Any:
        with self._register:
            return super().send_goal_async(*args, **kwargs)

    def _cancel_goal_async(self, goal_handle: Any) -> Any:
        with self._register:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle: Any) -> Any:
        with self._register:
            return super()._get_result_async(goal_handle)

    async def execute(self, taken_data: Any) -> None:
        with self._register:
            await super().execute(taken_data)


@dataclass
class Sent:
    """One goal sent: its handle, the feedback received (wall time, message), its result."""

    handle: Any
    feedback: list[tuple[float, Any]] = field(default_factory=list)


class TrajectoryActionClient:
    """FollowJointTrajectory on a node spun by the caller."""

    def __init__(self, node: Node, timeout_s: float = 30.0) -> None:
        self.client = _AtomicActionClient(
            node,
            FollowJointTrajectory,
            FOLLOW_JOINT_TRAJECTORY,
            feedback_sub_qos_profile=QoSProfile(depth=FEEDBACK_DEPTH),  # every tick's, kept
        )
        assert self.client.wait_for_server(timeout_sec=timeout_s), "no action server"

    def send(self, message: Any, timeout_s: float = 10.0) -> Sent:
        """Send ``message`` and wait for its acceptance."""
        feedback: list[tuple[float, Any]] = []
        future = self.client.send_goal_async(
            message, feedback_callback=lambda f: feedback.append((time.monotonic(), f.feedback))
        )
        wait_until(future.done, timeout_s, "the goal's acceptance")
        handle = future.result()
        assert handle.accepted, "the server rejected the goal"
        return Sent(handle, feedback)

    def rejected(self, message: Any, timeout_s: float = 10.0) -> bool:
        """Send ``message``; True when the server rejected it at goal time."""
        future = self.client.send_goal_async(message)
        wait_until(future.done, timeout_s, "the goal's response")
        return not future.result().accepted

    def result(self, sent: Sent, timeout_s: float = 30.0) -> tuple[int, Any]:
        """(status, result) once the goal has ended."""
        future = sent.handle.get_result_async()
        wait_until(future.done, timeout_s, "the goal's result")
        response = future.result()
        return int(response.status), response.result

    def cancel(self, sent: Sent, timeout_s: float = 10.0) -> Any:
        """Ask to cancel ``sent``; the cancel response."""
        future = sent.handle.cancel_goal_async()
        wait_until(future.done, timeout_s, "the cancel response")
        return future.result()

    def run(self, message: Any, timeout_s: float = 30.0) -> tuple[int, Any, Sent]:
        """Send ``message`` and wait for its end: (status, result, sent)."""
        sent = self.send(message)
        status, result = self.result(sent, timeout_s)
        return status, result, sent

    def destroy(self) -> None:
        self.client.destroy()


def ended(client: Any, message: Any, what: str = "the goal") -> tuple[int, Any]:
    """Send ``message`` through ``client``; assert it is accepted (10 s for the answer);
    (status, result) once it ends (30 s)."""
    sent = client.send_goal_async(message)
    wait_until(sent.done, 10.0, f"{what}'s answer")
    handle = sent.result()
    assert handle.accepted, f"{what} was rejected"
    result = handle.get_result_async()
    wait_until(result.done, 30.0, f"{what}'s result")
    return result.result().status, result.result().result


def succeeded(client: Any, message: Any, what: str = "the goal") -> Any:
    """Send ``message`` through ``client``; assert it is accepted and SUCCEEDED (10 s for the
    answer, 30 s for the result); the result."""
    from action_msgs.msg import GoalStatus

    status, result = ended(client, message, what)
    assert status == GoalStatus.STATUS_SUCCEEDED, result
    return result
