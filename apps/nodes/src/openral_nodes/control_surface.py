"""ControlSurface: the graph as ros2_control shows a robot, at the usual names.

For a simulated robot whose action is its manifest joints, the node offers what a stock
MoveIt or ros2_control client expects of a robot's driver, without the ``/openral`` prefix:

- ``joint_state_broadcaster``: ``/joint_states`` and ``/dynamic_joint_states``;
- ``joint_trajectory_controller``: ``follow_joint_trajectory``
  (:mod:`openral_nodes.trajectory_action`), ``joint_trajectory`` (the same rules as
  ``/openral/joint_trajectory``) and ``controller_state``
  (:mod:`openral_nodes.controller_state`), over the arm's joints;
- ``gripper_controller`` (a robot with a gripper whose modes allow it:
  :mod:`openral_nodes.gripper_wiring`): ``gripper_cmd`` (:mod:`openral_nodes.gripper_action`);
- ``/controller_manager``'s list and switch services (:mod:`openral_nodes.controller_manager`).

Deactivating a controller stops it as its namesake stops: the broadcaster publishes nothing,
the trajectory controller ends its goal (ABORTED) and refuses new ones, the gripper likewise.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from openral_bridge.control_loop import ControlLoop
from openral_bridge.topics import (
    GRIPPER_NAME,
    JSB_NAME,
    JTC_NAME,
    JTC_STATE,
    TopicInfo,
)
from openral_core.loaded import LoadedRobot
from openral_hal.protocol import RobotHal

from openral_nodes.controller_manager import Controller, ControllerManager
from openral_nodes.controller_state import ControllerStatePublisher
from openral_nodes.gripper_action import GripperAction
from openral_nodes.gripper_wiring import GripperAxis, gripper_axis

if TYPE_CHECKING:
    from collections.abc import Callable

    from openral_bridge.joint_state_publisher import JointStatePublisher
    from rclpy.node import Node

    from openral_nodes.trajectory_action import TrajectoryAction

Entity = tuple[str, Any]


class ControlSurface:
    """The controllers of one active node (see the module doc)."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        lock: threading.Lock,
        loop: ControlLoop | None,
        robot: LoadedRobot | None,
        on_refused: Callable[[str], None],
    ) -> None:
        self.node, self.hal, self.lock, self.loop, self.robot = node, hal, lock, loop, robot
        self.on_refused = on_refused
        self.manager: ControllerManager | None = None
        self.gripper: GripperAction | None = None
        self.state: ControllerStatePublisher | None = None
        self.action: TrajectoryAction | None = None

    def create(
        self, states: JointStatePublisher | None, action: TrajectoryAction | None
    ) -> list[Entity]:
        """Build the controllers over ``states`` (the broadcaster's publisher) and ``action``
        (the trajectory controller's, None: no trajectories here); serve the manager."""
        names = tuple(self.hal.action_names)
        controllers = [self._broadcaster(states, names)]
        entities: list[Entity] = []
        arm = names
        axis = gripper_axis(self.robot, names) if self.robot is not None else None
        loop = self.loop
        if loop is not None and action is not None and isinstance(axis, GripperAxis):
            self.gripper = GripperAction(self.node, self.hal, loop, axis, self.on_refused)
            self.gripper.create()
            arm = tuple(n for n in names if n != axis.joint)
            controllers.append(
                Controller(
                    GRIPPER_NAME,
                    "position_controllers/GripperActionController",
                    (axis.joint,),
                    (axis.joint,),
                    self.gripper.switch,
                )
            )
        elif isinstance(axis, str) and action is not None:
            self._log().info(f"no {GRIPPER_NAME}: {axis}")
        if loop is not None and action is not None and loop.follower is not None:
            self.action = action
            slots = tuple(names.index(n) for n in arm)
            self.state = ControllerStatePublisher(
                self.node, self.hal, self.lock, loop, loop.follower, slots
            )
            entities.append(self.state.start())
            controllers.insert(
                1,
                Controller(
                    JTC_NAME,
                    "joint_trajectory_controller/JointTrajectoryController",
                    arm,
                    arm,
                    self._switch_trajectories,
                ),
            )
        rate = 1.0 / loop.tick_period_s if loop is not None else 0.0
        self.manager = ControllerManager(self.node, controllers, names, rate)
        return entities + self.manager.create()

    def destroy(self) -> None:
        """Stop the gripper action and the controller state (the node removes the rest)."""
        if self.gripper is not None:
            self.gripper.destroy()
            self.gripper = None
        if self.state is not None:
            self.state.stop()
            self.state = None

    def trajectories_active(self) -> bool:
        """True while the trajectory controller takes trajectories."""
        return self.manager is None or self.manager.is_active(JTC_NAME)

    def stop_goals(self, reason: str) -> None:
        """End the gripper's running goal (the E-stop, a reset)."""
        if self.gripper is not None:
            self.gripper.stop_goal(reason)

    def topics(self) -> list[TopicInfo]:
        """The controller state topic (once per control period)."""
        if self.state is None or self.loop is None:
            return []
        kind = "control_msgs/msg/JointTrajectoryControllerState"
        return [TopicInfo(JTC_STATE, kind, 1.0 / self.loop.period_s)]

    def _broadcaster(
        self, states: JointStatePublisher | None, names: tuple[str, ...]
    ) -> Controller:
        def switch(active: bool) -> None:
            if states is not None:
                states.enabled = active

        return Controller(
            JSB_NAME, "joint_state_broadcaster/JointStateBroadcaster", (), names, switch
        )

    def _switch_trajectories(self, active: bool) -> None:
        if active or self.action is None:
            return
        self.action.stop_goal(f"the {JTC_NAME} was deactivated")
        if self.loop is not None and self.loop.follower is not None:
            self.loop.follower.cancel(f"the {JTC_NAME} was deactivated")

    def _log(self) -> Any:
        return self.node.get_logger()  # type: ignore[no-untyped-call]
