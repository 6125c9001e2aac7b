"""RobotStateStreams: what the manifest node publishes about the robot's own state.

- ``/joint_states`` and ``/openral/manifest_joint_states``
  (:class:`~openral_bridge.joint_state_publisher.JointStatePublisher`): after every tick of
  the control loop (a scene's state rate, a real driver's every reading: each a new stamp),
  or at a slower joint-state rate;
- ``/tf`` and ``/tf_static`` (:class:`~openral_bridge.tf_publisher.TfPublisher`; off with
  the ``publish_tf`` parameter) and the URDF on ``/robot_description``
  (:class:`~openral_bridge.description_publisher.DescriptionPublisher`), for a HAL with a
  frame tree (a native scene, or a real robot's model posed at its readings).

A model whose frames cannot be laid out as a tree is said once in the log; the graph then
runs without ``/tf`` and ``/robot_description`` and ``/joint_states`` carries the manifest's
joints.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from openral_bridge.control_loop import ControlLoop
from openral_bridge.description_publisher import DescriptionPublisher
from openral_bridge.joint_state_publisher import (
    HalStates,
    JointStatePublisher,
    StateSource,
    TickStates,
)
from openral_bridge.pacer import Pacer
from openral_bridge.tf_publisher import TfPublisher
from openral_bridge.topics import (
    DYNAMIC_JOINT_STATES,
    JOINT_STATES,
    MANIFEST_JOINT_STATES,
    ROBOT_DESCRIPTION_SEMANTIC,
    TopicInfo,
)
from openral_core.loaded import LoadedRobot
from openral_hal.errors import HalError
from openral_hal.protocol import FramesHal, MobileBaseHal, RobotHal
from openral_sim.frame_tree import FrameTree
from openral_sim.robot_description import (
    scene_robot_description,
    scene_semantic_description,
    urdf_transforms,
)

if TYPE_CHECKING:
    from rclpy.node import Node


class RobotStateStreams:
    """The joint-state, TF and description publishers of one active node."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        lock: threading.Lock,
        loop: ControlLoop | None,
        rate_hz: float,
        robot: LoadedRobot | None,
        tf: tuple[bool, bool] = (True, True),
        texts: tuple[str, str] | None = None,
    ) -> None:
        """Lay out the frames (nothing is published until :meth:`start`).

        Args:
            node: The node that owns the publishers and logs.
            hal: The connected HAL.
            lock: The HAL's lock.
            loop: The control loop of a simulated HAL (None for a real one).
            rate_hz: The joint-state rate, also the highest ``/tf`` rate [Hz].
            robot: The loaded robot (for its URDF).
            tf: (publish_tf, publish_static_tf). publish_tf False leaves the URDF's
                transforms to another node (a robot_state_publisher fed by our
                ``/joint_states`` and ``/robot_description``): only the frames no URDF
                holds are sent (the world, the odometry frame and the base on it, scene
                cameras); publish_static_tf False then leaves out the static ones of those
                too (a mobile base's moving transform is still sent).
            texts: The URDF and SRDF made beforehand (:func:`descriptions_before_connect`);
                None: made on threads after start.
        """
        self.node, self.loop = node, loop
        tree = self._frame_tree(hal) if loop is not None else None
        data = _data(hal) if tree is not None else None
        base = hal.base if isinstance(hal, MobileBaseHal) else None
        source: StateSource = HalStates(hal, lock)
        if loop is not None:
            source = TickStates(loop, tree.tree if tree else None, data, base)
        if loop is not None and hal.is_real:  # a reading per driver cycle
            rate_hz = 1.0 / loop.tick_period_s
        self.states = JointStatePublisher(node, rate_hz, source)
        self.tf = None
        publish_tf, publish_static_tf = tf
        if tree is not None and data is not None:
            leave_out = frozenset() if publish_tf else urdf_transforms(tree)
            tf_out = TfPublisher(
                node, tree, data, rate_hz, leave_out, publish_tf or publish_static_tf
            )
            self.tf = tf_out if len(tf_out.static) or len(tf_out.dynamic) else None
        self.description = self.semantic = None
        if tree is not None and robot is not None:
            name, loaded = robot.name, robot
            self.description = DescriptionPublisher(
                node, (lambda: texts[0]) if texts else (lambda: scene_robot_description(tree, name))
            )
            self.semantic = DescriptionPublisher(
                node,
                (lambda: texts[1]) if texts else (lambda: scene_semantic_description(tree, loaded)),
                ROBOT_DESCRIPTION_SEMANTIC,
            )

    def start(self, pacer: Pacer) -> None:
        """Publish the joint states and transforms once now, then on ``pacer``; start
        making the URDF."""
        self.states.start(pacer, self.loop)
        if self.tf is not None and self.loop is not None:
            self.tf.start(pacer, self.loop)
        for description in (self.description, self.semantic):
            if description is not None:
                description.start()

    def after_reset(self) -> None:
        """The static transforms again (a reset may move a camera and the odometry frame)."""
        if self.tf is not None:
            self.tf.publish_static()
            self.tf.publish()

    def stop(self) -> None:
        """Stop every publisher (idempotent)."""
        self.states.stop()
        if self.tf is not None:
            self.tf.stop()
        for description in (self.description, self.semantic):
            if description is not None:
                description.stop()

    def topics(self) -> list[TopicInfo]:
        """What these publish, with their nominal rates."""
        kind, rate = "sensor_msgs/msg/JointState", self.states.rate_hz
        rows = [TopicInfo(JOINT_STATES, kind, rate), TopicInfo(MANIFEST_JOINT_STATES, kind, rate)]
        rows.append(TopicInfo(DYNAMIC_JOINT_STATES, "control_msgs/msg/DynamicJointState", rate))
        rows += self.tf.topics() if self.tf is not None else []
        for description in (self.description, self.semantic):
            rows += description.topics() if description is not None else []
        return rows

    def _frame_tree(self, hal: RobotHal) -> FrameTree | None:
        if not isinstance(hal, FramesHal):
            return None
        try:
            return hal.frame_tree()
        except HalError as error:
            self._log().error(f"no /tf or /robot_description for this robot: {error}")
            return None

    def _log(self) -> Any:
        return self.node.get_logger()  # type: ignore[no-untyped-call]


def _data(hal: RobotHal) -> Any:
    """The HAL's live MuJoCo data (a FramesHal has it)."""
    handles = hal.mujoco_handles() if isinstance(hal, FramesHal) else None
    return handles[1] if handles is not None else None


def descriptions_before_connect(hal: RobotHal, robot: LoadedRobot | None) -> tuple[str, str] | None:
    """A real robot's URDF and SRDF, made before its driver starts (making them holds
    Python's lock for tens of milliseconds, which would stall the driver's loop); None for a
    simulated robot (made on threads after start) or one without frames.

    Raises:
        HalError: The robot's frames cannot be laid out as a tree.
    """
    if not hal.is_real or robot is None or not isinstance(hal, FramesHal):
        return None
    tree = hal.frame_tree()
    if tree is None:
        return None
    return scene_robot_description(tree, robot.name), scene_semantic_description(tree, robot)
