"""The ``control_msgs/action/FollowJointTrajectory`` server of the manifest node.

At :data:`~openral_bridge.topics.FOLLOW_JOINT_TRAJECTORY`, where ros2_control's
``joint_trajectory_controller`` serves it and MoveIt's simple controller manager looks for
it. It behaves as that controller does:

- a goal is checked when it arrives and REJECTED when it cannot run (an unknown, repeated or
  missing joint name, a trajectory that ended before now or starts implausibly late (a
  wall-clock stamp under simulated time), NaN, too many points, time going backwards, a
  first point too far from the joints, a bad tolerance, the E-stop latched, the controller
  deactivated); a rejection carries no reason in ROS, so the reason goes to the log and to
  ``/openral/joint_trajectory/refused``;
- an accepted goal's path is the one the control loop's
  :class:`~openral_bridge.trajectory_follower.TrajectoryFollower` follows next, the one that
  the ``joint_trajectory`` topic also feeds, under the same rules;
- every tick sends feedback (desired, actual and error of the goal's joints, stamped in
  simulated time) and judges the goal (:mod:`openral_bridge.trajectory_goal`): SUCCEEDED,
  or ABORTED with PATH_TOLERANCE_VIOLATED / GOAL_TOLERANCE_VIOLATED (the joints then hold);
- a newer goal pre-empts the running one, and so do a trajectory on the topic, a
  ``safe_action``, the E-stop, a reset and deactivating the controller: ABORTED,
  INVALID_GOAL (the controller's code for a goal it did not finish), the cause in
  ``error_string``;
- a cancel request of the running goal stops the path at once (the next tick holds the
  joints at their set points) and the goal ends CANCELED.

Goals are ended by the control loop (:class:`~openral_nodes.loop_driven_server.LoopDrivenServer`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from control_msgs.action import FollowJointTrajectory
from openral_bridge.control_loop import ControlLoop
from openral_bridge.joint_path import JointPath, PathRefused
from openral_bridge.joint_state_publisher import sim_stamp
from openral_bridge.topics import FOLLOW_JOINT_TRAJECTORY, JTC_NAME
from openral_bridge.trajectory_follower import TrajectoryFollower
from openral_bridge.trajectory_goal import Outcome, Progress, Tolerances, judge
from openral_core.models import TrajectoryRules
from openral_hal.protocol import RobotHal
from openral_mujoco.state import JointStateSample
from rclpy.action.server import CancelResponse, GoalResponse
from rclpy.qos import QoSProfile
from trajectory_msgs.msg import JointTrajectoryPoint

from openral_nodes.graph_names import graph_name
from openral_nodes.loop_driven_server import LoopDrivenServer
from openral_nodes.trajectory_request import goal_request

if TYPE_CHECKING:
    from rclpy.node import Node

Result = FollowJointTrajectory.Result
RESULT_TIMEOUT_S = 30
"""How long a finished goal's result is kept for a client that asks late [s] (bounds what a
flood of goals can hold)."""
VIOLATIONS = {
    Outcome.PATH_TOLERANCE_VIOLATED: Result.PATH_TOLERANCE_VIOLATED,
    Outcome.GOAL_TOLERANCE_VIOLATED: Result.GOAL_TOLERANCE_VIOLATED,
}
FEEDBACK_DEPTH = 100
"""Feedback messages kept for a client that reads late (1 s at a 100 Hz state rate; rclpy's
default, 10, lost 8 of 301 to a client held up for a moment in a fresh clone's run)."""


@dataclass(eq=False)
class _Goal:
    """One accepted goal and its path."""

    handle: Any
    path: JointPath
    tolerances: Tolerances
    feedback: Any = field(default_factory=FollowJointTrajectory.Feedback)
    cancelling: bool = False
    finished: bool = False


class TrajectoryAction:
    """The FollowJointTrajectory action of one active manifest node (see the module doc)."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        lock: threading.Lock,
        loop: ControlLoop,
        follower: TrajectoryFollower,
        rules: TrajectoryRules,
        on_refused: Callable[[str], None] = lambda reason: None,
        active: Callable[[], bool] = lambda: True,
    ) -> None:
        """Nothing is served until :meth:`create`; ``on_refused`` gets each rejection's
        reason, ``active`` says whether the controller takes goals."""
        self.node, self.hal, self.lock, self.loop = node, hal, lock, loop
        self.follower, self.rules = follower, rules
        self.on_refused, self.active = on_refused, active
        self._planned: tuple[Any, JointPath, Tolerances] | None = None
        self.accepted = 0
        """Goals that became the follower's path."""
        self.refused = 0
        """Goals rejected."""
        self._active: _Goal | None = None
        self._goals_lock = threading.Lock()
        self._server: LoopDrivenServer | None = None

    def create(self) -> None:
        """Start serving; the follower tells this action when a path ends early."""
        self.follower.on_end = self._path_ended
        self.loop.watchers.append(self._on_tick)
        self._server = LoopDrivenServer(  # type: ignore[no-untyped-call]
            self.node,
            FollowJointTrajectory,
            graph_name(self.node, FOLLOW_JOINT_TRAJECTORY),
            execute_callback=lambda handle: Result(),
            goal_callback=self._on_goal,
            handle_accepted_callback=self._on_accepted,
            cancel_callback=self._on_cancel,
            result_timeout=RESULT_TIMEOUT_S,
            feedback_pub_qos_profile=QoSProfile(depth=FEEDBACK_DEPTH),  # type: ignore[no-untyped-call]
        )

    def destroy(self) -> None:
        """Abort the running goal and stop serving."""
        with self._goals_lock:
            goal, self._active = self._active, None
        if goal is not None:
            self._end(goal, "abort", Result.INVALID_GOAL, "the controller stopped")
        if self._on_tick in self.loop.watchers:
            self.loop.watchers.remove(self._on_tick)
        if self._server is not None:
            self._server.destroy()  # type: ignore[no-untyped-call]
            self._server = None

    # -- goals (executor thread) -------------------------------------------------------------

    def _on_goal(self, goal: Any) -> Any:
        """Check ``goal`` and make its path the follower's next one: ACCEPT, or REJECT with
        the reason logged and published."""
        try:
            if not self.active():
                raise PathRefused(f"the {JTC_NAME} is inactive (switch_controller activates it)")
            path, tolerances = self._plan(goal)
        except PathRefused as error:
            self.refused += 1
            self._log().warning(
                f"{FOLLOW_JOINT_TRAJECTORY}: goal rejected: {error}", throttle_duration_sec=2.0
            )
            self.on_refused(str(error))
            return GoalResponse.REJECT
        self._planned = (goal, path, tolerances)
        return GoalResponse.ACCEPT

    def _on_accepted(self, handle: Any) -> None:
        handle.execute()
        planned, self._planned = self._planned, None
        if planned is None or planned[0] is not handle.request:  # never: accepted = planned
            self._finish_now(handle, "abort", Result.INVALID_GOAL, "the goal was not planned")
            return
        _, path, tolerances = planned
        feedback = FollowJointTrajectory.Feedback(joint_names=list(path.names))
        goal = _Goal(handle, path, tolerances, feedback)
        self.accepted += 1
        with self._goals_lock:
            previous, self._active = self._active, goal
        if previous is not None:
            self._end(previous, "abort", Result.INVALID_GOAL, "pre-empted by a newer goal")

    def _plan(self, goal: Any) -> tuple[JointPath, Tolerances]:
        """Check the goal and make its path the follower's next one."""
        request, tolerances = goal_request(goal, self.rules)
        if self.hal.estopped:
            raise PathRefused("the E-stop is latched")
        with self.lock:
            hold = np.asarray(self.hal.hold_action(), dtype=np.float64)
            state = self.loop.state
        if state is None or state.sim_time_s is None:
            raise PathRefused("the scene has no simulated time yet")
        return self.follower.submit(request, hold, state.sim_time_s, state.positions), tolerances

    def stop_goal(self, reason: str) -> None:
        """End the running goal (ABORTED, INVALID_GOAL, ``reason``) and its path: the
        controller was deactivated."""
        goal = self._active
        if goal is not None:
            self._end(goal, "abort", Result.INVALID_GOAL, reason)
            self.follower.cancel(reason, goal.path)

    def _on_cancel(self, handle: Any) -> Any:
        goal = self._active
        if goal is None or goal.handle is not handle or goal.finished:
            return CancelResponse.REJECT
        goal.cancelling = True
        self.follower.cancel("the goal was cancelled", goal.path)  # the next tick holds
        executor = self.node.executor
        if executor is not None:  # after rclpy has moved the goal to CANCELING
            executor.create_task(self._end, goal, "canceled", Result.SUCCESSFUL, "cancelled")
        return CancelResponse.ACCEPT

    # -- the control loop's thread -----------------------------------------------------------

    def _on_tick(self, state: JointStateSample) -> None:
        """Feedback and judgement of the running goal after a tick."""
        goal = self._active
        if goal is None or goal.cancelling or state.sim_time_s is None:
            return
        now_s = state.sim_time_s
        progress = judge(goal.path, goal.tolerances, state.positions, state.velocities, now_s)
        self._feedback(goal, progress)
        if progress.outcome is Outcome.SUCCEEDED:
            self._end(goal, "succeed", Result.SUCCESSFUL, progress.message)
        elif progress.outcome in VIOLATIONS:
            self._end(goal, "abort", VIOLATIONS[progress.outcome], progress.message)
            self.follower.cancel(progress.message, goal.path)  # hold where they are

    def _path_ended(self, path: JointPath, reason: str) -> None:
        """The follower ended ``path`` early (any thread)."""
        goal = self._active
        if goal is not None and goal.path is path and not goal.cancelling:
            self._end(goal, "abort", Result.INVALID_GOAL, f"the trajectory stopped: {reason}")

    def _feedback(self, goal: _Goal, progress: Progress) -> None:
        feedback = goal.feedback
        feedback.header.stamp = sim_stamp(self.node, progress.time_s)
        feedback.desired = _point(progress.desired_positions, progress.desired_velocities)
        feedback.actual = _point(progress.actual_positions, progress.actual_velocities)
        feedback.error = _point(progress.error_positions, progress.error_velocities)
        goal.handle.publish_feedback(feedback)

    # -- endings (any thread) ----------------------------------------------------------------

    def _end(self, goal: _Goal, status: str, code: int, message: str) -> None:
        """End ``goal`` once (later calls do nothing)."""
        with self._goals_lock:
            if goal.finished:
                return
            goal.finished = True
            if self._active is goal:
                self._active = None
        self._finish_now(goal.handle, status, code, message)

    def _finish_now(self, handle: Any, status: str, code: int, message: str) -> None:
        if self._server is not None:
            self._server.finish(handle, status, Result(error_code=code, error_string=message))

    def _log(self) -> Any:
        return self.node.get_logger()  # type: ignore[no-untyped-call]


def _point(positions: Any, velocities: Any) -> Any:
    return JointTrajectoryPoint(
        positions=np.asarray(positions, np.float64).tolist(),
        velocities=np.asarray(velocities, np.float64).tolist(),
    )
