"""The wire to a ros2_control robot driver: its joint states in, trajectories and gripper
goals out, on a ROS 2 context of the link's own.

The link knows ROS and names, nothing of the robot's safety: what to send and when is
:class:`~openral_real.ros2_control_hal.Ros2ControlHal`'s. It runs one executor thread of
its own, so the driver's readings arrive whatever the caller's graph is doing, and it is
isolated from the caller's nodes (its own ``rclpy`` context, on the process's
``ROS_DOMAIN_ID``, which ``deploy real --domain-id`` sets).

Two nodes, two threads: the readings' node holds nothing but the joint state subscription
and its thread (real-time scheduled where allowed) does nothing but take them; the
commands' node (trajectory publisher or action client, gripper action client) is spun by
an ordinary thread. An action client's status and feedback messages (the gripper's come
every driver period while a goal runs) then never delay a reading: on 2 shared cores a
single thread for both took readings up to 30 ms after they arrived, past the two-period
rule.

Names are the driver's, under its namespace: ``/<ns>/<joint_state_topic>``,
``/<ns>/<controller>/joint_trajectory`` (or ``follow_joint_trajectory``) and
``/<ns>/<gripper_action>``, as ros2_control's joint_state_broadcaster,
joint_trajectory_controller and gripper action controllers offer them.
"""

from __future__ import annotations

import contextlib
import re
import threading
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from openral_core.real_wiring import Ros2ControlWiring
from openral_hal.errors import ConfigurationError
from openral_hal.realtime import answer_first
from openral_hal.unlocked_publisher import UnlockedPublisher
from openral_mujoco.state import FloatArray

__all__ = ["JointReading", "Ros2ControlLink", "driver_namespace"]

NAMESPACE = re.compile(r"^(/?[A-Za-z][A-Za-z0-9_]*)*$")
"""A ROS namespace: tokens of letters, digits and underscores (empty: the root)."""
JOINT_STATE_DEPTH = 5
"""Readings queued for the link's thread; the newest wins."""
GOAL_TIMEOUT_S = 5.0
"""Longest wait for the gripper's action server to answer a goal [s]."""

JointReading = tuple[dict[str, tuple[float, float, float]], float]
"""A joint state message as name → (position, velocity, effort), with its stamp [s]."""


def driver_namespace(transport: str | None) -> str:
    """The robot driver's namespace in ``ros2_control:<namespace>`` (leading ``/`` added).

    Raises:
        ConfigurationError: Not of that form, or not a ROS namespace.
    """
    prefix = "ros2_control:"
    if not transport or not transport.startswith(prefix):
        raise ConfigurationError(
            f"the ros2_control driver takes --transport ros2_control:<namespace> (the robot "
            f"driver's namespace, e.g. ros2_control:/panda), got {transport!r}"
        )
    namespace = transport[len(prefix) :].strip("/")
    if not NAMESPACE.match(namespace):
        raise ConfigurationError(
            f"--transport {transport!r}: {namespace!r} is not a ROS namespace (letters, "
            "digits and underscores, tokens joined by '/', each starting with a letter)"
        )
    return "/" + namespace if namespace else ""


class Ros2ControlLink:
    """One robot driver's topics and actions (see the module doc)."""

    def __init__(
        self, wiring: Ros2ControlWiring, namespace: str, on_reading: Callable[[JointReading], None]
    ) -> None:
        """Nothing is opened until :meth:`open`; ``on_reading`` runs on the readings' thread."""
        self.wiring, self.namespace, self.on_reading = wiring, namespace, on_reading
        self._context: Any = None
        self._node: Any = None
        self._commands_node: Any = None
        self._executors: list[Any] = []
        self._threads: list[threading.Thread] = []
        self._trajectory: Any = None
        self._follow: Any = None
        self._gripper: Any = None
        self._gripper_goal: Any = None
        self._goal_lock = threading.Lock()

    def name(self, relative: str) -> str:
        """``relative`` under the driver's namespace."""
        return f"{self.namespace}/{relative}"

    # -- lifecycle ---------------------------------------------------------------------------

    def open(self) -> None:
        """Start a context, a node and its executor thread, and subscribe to the readings."""
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rclpy.signals import SignalHandlerOptions
        from sensor_msgs.msg import JointState
        from trajectory_msgs.msg import JointTrajectory

        self._context = Context()  # on ROS_DOMAIN_ID; the caller's signal handlers stay
        rclpy.init(context=self._context, signal_handler_options=SignalHandlerOptions.NO)
        self._node = Node("openral_ros2_control_link", context=self._context)
        commands = Node("openral_ros2_control_commands", context=self._context)
        self._commands_node = commands
        readings = QoSProfile(  # type: ignore[no-untyped-call]
            depth=JOINT_STATE_DEPTH, reliability=ReliabilityPolicy.BEST_EFFORT
        )
        self._node.create_subscription(
            JointState, self.name(self.wiring.joint_state_topic), self._reading, readings
        )
        controller = self.wiring.controller
        if self.wiring.command_interface == "topic":
            topic = self.name(f"{controller}/joint_trajectory")
            self._trajectory = commands.create_publisher(
                JointTrajectory, topic, 10, publisher_class=UnlockedPublisher
            )
        else:
            from control_msgs.action import FollowJointTrajectory
            from rclpy.action.client import ActionClient

            action = self.name(f"{controller}/follow_joint_trajectory")
            self._follow = ActionClient(commands, FollowJointTrajectory, action)  # type: ignore[no-untyped-call]
        if self.wiring.gripper_action is not None:
            from control_msgs.action import GripperCommand
            from rclpy.action.client import ActionClient

            gripper = self.name(self.wiring.gripper_action)
            self._gripper = ActionClient(commands, GripperCommand, gripper)  # type: ignore[no-untyped-call]
        self._executors = []
        for node, name, first in ((self._node, "readings", True), (commands, "commands", False)):
            executor = SingleThreadedExecutor(context=self._context)
            executor.add_node(node)
            self._executors.append(executor)
            thread = threading.Thread(
                target=self._spin, args=(executor, first), name=f"openral-ros2-{name}", daemon=True
            )
            self._threads.append(thread)
            thread.start()

    def close(self) -> None:
        """Stop the thread and shut the context down (idempotent)."""
        import rclpy

        executors, self._executors = self._executors, []
        for executor in executors:
            executor.shutdown(timeout_sec=2.0)
        threads, self._threads = self._threads, []
        for thread in threads:
            thread.join(5.0)
        for node in (self._node, self._commands_node):
            if node is not None:
                node.destroy_node()
        self._node = self._commands_node = None
        if self._context is not None:
            rclpy.shutdown(context=self._context)
            self._context = None

    # -- commands ----------------------------------------------------------------------------

    def send_point(self, joints: Sequence[str], positions: FloatArray, after_s: float) -> None:
        """A one-point trajectory: ``joints`` (the driver's names) at ``positions`` reached
        ``after_s`` from now; it replaces whatever the controller was following."""
        from builtin_interfaces.msg import Duration
        from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

        nanoseconds = round(after_s * 1e9)
        point = JointTrajectoryPoint(
            positions=[float(v) for v in np.asarray(positions)],
            time_from_start=Duration(sec=nanoseconds // 10**9, nanosec=nanoseconds % 10**9),
        )
        message = JointTrajectory(joint_names=list(joints), points=[point])
        if self._trajectory is not None:
            self._trajectory.publish(message)
        elif self._follow is not None:
            from control_msgs.action import FollowJointTrajectory

            self._follow.send_goal_async(FollowJointTrajectory.Goal(trajectory=message))

    def send_gripper(self, position: float, max_effort: float) -> None:
        """A GripperCommand goal (the driver's units: metres or radians, newtons); a goal
        still running is replaced, as the gripper controllers do."""
        if self._gripper is None:
            return
        from control_msgs.action import GripperCommand

        goal = GripperCommand.Goal()
        goal.command.position, goal.command.max_effort = float(position), float(max_effort)
        future = self._gripper.send_goal_async(goal)
        future.add_done_callback(self._gripper_accepted)

    def cancel_gripper(self) -> None:
        """Cancel the gripper's goal in flight, if any."""
        with self._goal_lock:
            handle, self._gripper_goal = self._gripper_goal, None
        if handle is not None:
            handle.cancel_goal_async()

    def driver_ready(self) -> str | None:
        """None when every server the link needs is up, else what is missing (one line)."""
        missing = []
        if self._follow is not None and not self._follow.server_is_ready():
            missing.append(self.name(f"{self.wiring.controller}/follow_joint_trajectory"))
        if self._gripper is not None and not self._gripper.server_is_ready():
            missing.append(self.name(str(self.wiring.gripper_action)))
        if self._trajectory is not None and not self._trajectory.get_subscription_count():
            missing.append(self.name(f"{self.wiring.controller}/joint_trajectory"))
        return f"no server of {', '.join(missing)}" if missing else None

    # -- the link's thread -------------------------------------------------------------------

    def _spin(self, executor: Any, first: bool) -> None:
        """Spin ``executor`` until it is shut down; ``first``: ask real-time scheduling (the
        readings' thread: each reading is one cycle of the driver's loop here)."""
        from rclpy.executors import ExternalShutdownException

        if first:
            answer_first()
        with contextlib.suppress(ExternalShutdownException, RuntimeError):  # closing
            executor.spin()  # no timeout: a timer made per wait costs more than the wait

    def _reading(self, message: Any) -> None:
        count = len(message.name)
        values = {
            str(message.name[i]): (
                float(message.position[i]) if i < len(message.position) else float("nan"),
                float(message.velocity[i]) if i < len(message.velocity) else 0.0,
                float(message.effort[i]) if i < len(message.effort) else 0.0,
            )
            for i in range(count)
        }
        stamp_s = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
        self.on_reading((values, stamp_s))

    def _gripper_accepted(self, future: Any) -> None:
        handle = future.result()
        if handle is not None and handle.accepted:
            with self._goal_lock:
                self._gripper_goal = handle
