"""``gripper_controller``: a parallel gripper's ``control_msgs/action/GripperCommand``.

At :data:`~openral_bridge.topics.GRIPPER_COMMAND`, where MoveIt's gripper handler and most
apps look for it, for a robot whose manifest has a gripper. It behaves as ros2_control's
``position_controllers/GripperActionController`` with ``allow_stalling: true``:

- ``command.position`` is the gripper joint's position as the URDF and ``/joint_states``
  give it (the Panda's ``panda_finger_joint1``: metres per finger, 0 closed, 0.04 open).
  A goal is REJECTED (reason logged and on ``/openral/joint_trajectory/refused``) when the
  position is not finite or outside the manifest's limits, the E-stop is latched or the
  controller is inactive; ``max_effort`` is not applied (a position-controlled gripper, as
  upstream's position variant) but must be finite;
- an accepted goal sets the gripper's slot of the next control period, on top of what the
  arm does (a running arm trajectory goes on); every tick sends feedback;
- it ends SUCCEEDED with ``reached_goal`` once within :data:`GOAL_TOLERANCE` of the goal,
  or SUCCEEDED with ``stalled`` when the gripper has not moved faster than
  :data:`STALL_VELOCITY` for :data:`STALL_TIMEOUT_S` of simulated time (closed on an
  object); result and feedback carry the position, effort, ``stalled`` and ``reached_goal``;
- a newer goal, the E-stop, a reset or deactivation end it ABORTED; a cancel holds the
  gripper where it is and ends it CANCELED.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from control_msgs.action import GripperCommand
from openral_bridge.control_loop import ControlLoop
from openral_bridge.topics import GRIPPER_COMMAND, GRIPPER_NAME
from openral_hal.protocol import RobotHal
from openral_mujoco.state import JointStateSample
from rclpy.action.server import CancelResponse, GoalResponse

from openral_nodes.graph_names import graph_name
from openral_nodes.gripper_wiring import GripperAxis
from openral_nodes.loop_driven_server import LoopDrivenServer

if TYPE_CHECKING:
    from collections.abc import Callable

    from rclpy.node import Node

GOAL_TOLERANCE = 0.01
"""Distance to the goal position at which it counts as reached (upstream's default)."""
STALL_VELOCITY = 0.001
"""Speed below which the gripper counts as not moving (upstream's default) [unit/s]."""
STALL_TIMEOUT_S = 1.0
"""Simulated time without movement after which the gripper has stalled [s]."""


@dataclass(eq=False)
class _Goal:
    handle: Any
    target: float
    moved_s: float
    """Simulated time the gripper was last seen moving [s]."""
    finished: bool = False


class GripperAction:
    """The GripperCommand server of one active node (see the module doc)."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        loop: ControlLoop,
        axis: GripperAxis,
        on_refused: Callable[[str], None],
    ) -> None:
        self.node, self.hal, self.loop, self.axis = node, hal, loop, axis
        self.on_refused = on_refused
        self.active = True
        """False while the controller is deactivated (goals are rejected)."""
        self.accepted = self.refused = 0
        self._goal: _Goal | None = None
        self._lock = threading.Lock()
        self._server: LoopDrivenServer | None = None

    def create(self) -> None:
        """Start serving; judge the goal after every tick."""
        self.loop.watchers.append(self._on_tick)
        self._server = LoopDrivenServer(  # type: ignore[no-untyped-call]
            self.node,
            GripperCommand,
            graph_name(self.node, GRIPPER_COMMAND),
            execute_callback=lambda handle: GripperCommand.Result(),
            goal_callback=self._on_goal,
            handle_accepted_callback=self._on_accepted,
            cancel_callback=self._on_cancel,
            result_timeout=30,
        )

    def destroy(self) -> None:
        """End the running goal and stop serving."""
        self.stop_goal("the controller stopped")
        if self._on_tick in self.loop.watchers:
            self.loop.watchers.remove(self._on_tick)
        if self._server is not None:
            self._server.destroy()  # type: ignore[no-untyped-call]
            self._server = None

    def switch(self, active: bool) -> None:
        """Activate or deactivate (a running goal ends ABORTED)."""
        self.active = active
        if not active:
            self.stop_goal(f"the {GRIPPER_NAME} was deactivated")

    def stop_goal(self, reason: str) -> None:
        """End the running goal ABORTED with ``reason`` (any thread)."""
        goal = self._goal
        if goal is not None:
            self._end(goal, "abort", self._result(None, stalled=False, reached=False), reason)

    # -- executor thread ---------------------------------------------------------------

    def _on_goal(self, goal: Any) -> Any:
        position, effort = float(goal.command.position), float(goal.command.max_effort)
        low, high = self.axis.limits
        reason = None
        if not self.active:
            reason = f"the {GRIPPER_NAME} is inactive (switch_controller activates it)"
        elif self.hal.estopped:
            reason = "the E-stop is latched"
        elif not (math.isfinite(position) and math.isfinite(effort)):
            reason = f"command ({position}, {effort}) is not finite"
        elif not low - 1e-9 <= position <= high + 1e-9:
            reason = (
                f"position {position:g} is outside {self.axis.joint}'s limits [{low:g}, {high:g}]"
            )
        if reason is not None:
            self.refused += 1
            self._log().warning(f"{GRIPPER_COMMAND}: goal rejected: {reason}")
            self.on_refused(reason)
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _on_accepted(self, handle: Any) -> None:
        handle.execute()
        target = float(handle.request.command.position)
        state = self.loop.state
        now_s = state.sim_time_s if state is not None and state.sim_time_s is not None else 0.0
        goal = _Goal(handle, target, now_s)
        with self._lock:
            previous, self._goal = self._goal, goal
        if previous is not None:
            self._end(
                previous, "abort", self._result(None, False, False), "pre-empted by a newer goal"
            )
        self.accepted += 1
        self.loop.command_slots({self.axis.slot: self.axis.command(target)})

    def _on_cancel(self, handle: Any) -> Any:
        goal = self._goal
        if goal is None or goal.handle is not handle or goal.finished:
            return CancelResponse.REJECT
        state = self.loop.state
        if state is not None:  # hold where it is
            self.loop.command_slots({self.axis.slot: self.axis.command(self.axis.position(state))})
        executor = self.node.executor
        if executor is not None:
            result = self._result(state, stalled=False, reached=False)
            executor.create_task(self._end, goal, "canceled", result, "cancelled")
        return CancelResponse.ACCEPT

    # -- the control loop's thread -------------------------------------------------------

    def _on_tick(self, state: JointStateSample) -> None:
        goal = self._goal
        if goal is None or goal.finished or state.sim_time_s is None:
            return
        position, speed = self.axis.position(state), self.axis.speed(state)
        reached = abs(goal.target - position) < GOAL_TOLERANCE
        if abs(speed) > STALL_VELOCITY:
            goal.moved_s = state.sim_time_s
        stalled = not reached and state.sim_time_s - goal.moved_s > STALL_TIMEOUT_S
        feedback = GripperCommand.Feedback()
        feedback.position, feedback.effort = position, self.axis.effort(state)
        feedback.stalled, feedback.reached_goal = stalled, reached
        goal.handle.publish_feedback(feedback)
        if reached or stalled:
            self._end(goal, "succeed", self._result(state, stalled, reached), "")

    # -- endings -------------------------------------------------------------------------

    def _result(self, state: JointStateSample | None, stalled: bool, reached: bool) -> Any:
        state = state if state is not None else self.loop.state
        result = GripperCommand.Result(stalled=stalled, reached_goal=reached)
        if state is not None:
            result.position, result.effort = self.axis.position(state), self.axis.effort(state)
        return result

    def _end(self, goal: _Goal, status: str, result: Any, reason: str) -> None:
        with self._lock:
            if goal.finished:
                return
            goal.finished = True
            if self._goal is goal:
                self._goal = None
        if reason and status == "abort":
            self._log().info(f"{GRIPPER_COMMAND}: goal aborted: {reason}")
        if self._server is not None:
            self._server.finish(goal.handle, status, result)

    def _log(self) -> Any:
        return self.node.get_logger()  # type: ignore[no-untyped-call]
