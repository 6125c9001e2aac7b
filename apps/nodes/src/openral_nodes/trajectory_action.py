"""The ``control_msgs/action/FollowJointTrajectory`` server of the manifest node.

At :data:`~openral_bridge.topics.FOLLOW_JOINT_TRAJECTORY`, the name MoveIt's
``moveit_simple_controller_manager`` reaches for a controller called
``joint_trajectory_controller``. It follows ros2_control's joint_trajectory_controller:

- every goal is accepted, then checked: a bad one ends at once, ABORTED, with the controller's
  result codes and the reason in ``error_string`` (INVALID_JOINTS for an unknown, repeated or
  missing joint name, OLD_HEADER_TIMESTAMP for a trajectory that ended before now,
  INVALID_GOAL for anything else: NaN, too many points, time going backwards, a bad
  tolerance, the E-stop latched). Unlike ros2_control, which rejects such goals with no
  reason, the client learns why;
- a valid goal becomes the path of the control loop's
  :class:`~openral_bridge.trajectory_follower.TrajectoryFollower`, the one that
  ``/openral/joint_trajectory`` also feeds, under the same rules (start tolerance, limits);
- every control tick sends feedback (desired, actual and error of the goal's joints, stamped
  in simulated time) and judges the goal (:mod:`openral_bridge.trajectory_goal`): SUCCEEDED,
  or ABORTED with PATH_TOLERANCE_VIOLATED / GOAL_TOLERANCE_VIOLATED (the joints then hold
  where they are);
- a newer goal pre-empts the running one (ABORTED, INVALID_GOAL, "pre-empted by a newer
  goal", as the controller does); so does a trajectory on the topic, a ``safe_action``, the
  E-stop or a reset (ABORTED, INVALID_GOAL, with what ended it);
- a cancel request of the running goal stops the path at once: the next tick holds the
  joints where their set points are, and the goal ends CANCELED.

rclpy runs an action's execute callback as a coroutine that its executor polls on every
spin while it waits (a busy loop on the only executor thread); here no callback waits: a
goal is started by its accept callback and finished by the control loop, which schedules the
ending on the executor (:class:`_LoopDrivenServer`).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from control_msgs.action import FollowJointTrajectory
from openral_bridge.control_loop import ControlLoop
from openral_bridge.joint_path import JointPath, PathRefused, Refusal
from openral_bridge.joint_state_publisher import sim_stamp
from openral_bridge.topics import FOLLOW_JOINT_TRAJECTORY
from openral_bridge.trajectory_follower import TrajectoryFollower
from openral_bridge.trajectory_goal import Outcome, Progress, Tolerances, judge
from openral_core.models import TrajectoryRules
from openral_hal.protocol import RobotHal
from openral_mujoco.state import JointStateSample
from rclpy.action.server import ActionServer, CancelResponse, GoalResponse
from trajectory_msgs.msg import JointTrajectoryPoint

from openral_nodes.trajectory_request import goal_request

if TYPE_CHECKING:
    from rclpy.node import Node

Result = FollowJointTrajectory.Result
RESULT_TIMEOUT_S = 30
"""How long a finished goal's result is kept for a client that asks late [s] (bounds what a
flood of goals can hold)."""
CODES = {
    Refusal.INVALID_GOAL: Result.INVALID_GOAL,
    Refusal.INVALID_JOINTS: Result.INVALID_JOINTS,
    Refusal.OLD_HEADER_TIMESTAMP: Result.OLD_HEADER_TIMESTAMP,
}
VIOLATIONS = {
    Outcome.PATH_TOLERANCE_VIOLATED: Result.PATH_TOLERANCE_VIOLATED,
    Outcome.GOAL_TOLERANCE_VIOLATED: Result.GOAL_TOLERANCE_VIOLATED,
}


@dataclass(eq=False)
class _Goal:
    """One accepted goal and its path."""

    handle: Any
    path: JointPath
    tolerances: Tolerances
    feedback: Any = field(default_factory=FollowJointTrajectory.Feedback)
    cancelling: bool = False
    finished: bool = False


class _LoopDrivenServer(ActionServer):
    """An ActionServer whose goals end when the control loop says so (see the module doc):
    ``goal_handle.execute()`` only marks the goal executing; :meth:`finish` ends it."""

    def notify_execute(self, goal_handle: Any, execute_callback: Any) -> None:
        if execute_callback is not None:
            super().notify_execute(goal_handle, execute_callback)  # type: ignore[no-untyped-call]

    def finish(self, goal_handle: Any, status: str, result: Any) -> None:
        """End ``goal_handle`` (any thread): on the executor, move it to ``status``
        (``succeed``, ``abort`` or ``canceled``) and hand ``result`` to its client."""

        def end(handle: Any) -> Any:
            try:
                if handle.is_active:
                    getattr(handle, status)()
            except Exception:  # a transition the goal's state no longer allows: abort it
                if handle.is_active:
                    handle.abort()
            return result

        super().notify_execute(goal_handle, end)  # type: ignore[no-untyped-call]


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
    ) -> None:
        self.node, self.hal, self.lock, self.loop = node, hal, lock, loop
        self.follower, self.rules = follower, rules
        self.accepted = 0
        """Goals that became the follower's path."""
        self.refused = 0
        """Goals ended at once for a bad trajectory."""
        self._active: _Goal | None = None
        self._goals_lock = threading.Lock()
        self._server: _LoopDrivenServer | None = None

    def create(self) -> None:
        """Start serving; the follower tells this action when a path ends early."""
        self.follower.on_end = self._path_ended
        self.loop.watchers.append(self._on_tick)
        self._server = _LoopDrivenServer(  # type: ignore[no-untyped-call]
            self.node,
            FollowJointTrajectory,
            FOLLOW_JOINT_TRAJECTORY,
            execute_callback=lambda handle: Result(),
            goal_callback=lambda goal: GoalResponse.ACCEPT,
            handle_accepted_callback=self._on_accepted,
            cancel_callback=self._on_cancel,
            result_timeout=RESULT_TIMEOUT_S,
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

    def _on_accepted(self, handle: Any) -> None:
        handle.execute()
        try:
            goal = self._start(handle)
        except PathRefused as error:
            self.refused += 1
            self._log().warning(
                f"{FOLLOW_JOINT_TRAJECTORY}: goal refused: {error}", throttle_duration_sec=2.0
            )
            self._finish_now(handle, "abort", CODES[error.kind], str(error))
            return
        self.accepted += 1
        with self._goals_lock:
            previous, self._active = self._active, goal
        if previous is not None:
            self._end(previous, "abort", Result.INVALID_GOAL, "pre-empted by a newer goal")

    def _start(self, handle: Any) -> _Goal:
        """Check the goal and make its path the follower's next one."""
        request, tolerances = goal_request(handle.request, self.rules)
        if self.hal.estopped:
            raise PathRefused("the E-stop is latched")
        with self.lock:
            hold = np.asarray(self.hal.hold_action(), dtype=np.float64)
            state = self.loop.state
        if state is None or state.sim_time_s is None:
            raise PathRefused("the scene has no simulated time yet")
        path = self.follower.submit(request, hold, state.sim_time_s, state.positions)
        feedback = FollowJointTrajectory.Feedback(joint_names=list(path.names))
        return _Goal(handle, path, tolerances, feedback)

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
