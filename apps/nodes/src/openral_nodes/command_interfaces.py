"""What a client commands on the manifest node while it is active.

- ``/openral/safe_action`` (``std_msgs/Float64MultiArray``): one value per action slot;
  a valid one waits for the next control tick (on a real HAL: goes to it at once) and
  pre-empts a running joint trajectory;
- ``/openral/joint_trajectory`` (``trajectory_msgs/JointTrajectory``): joints by manifest
  name, followed by the control loop (:mod:`openral_bridge.joint_path` says what is
  accepted); ``/openral/joint_trajectory/state`` (``sensor_msgs/JointState``) carries the
  desired point after every tick that followed one, stamped in simulated time; a refused
  trajectory's reason is published on ``/openral/joint_trajectory/refused``
  (``std_msgs/String``), every one of them, since a topic has no reply;
- the FollowJointTrajectory action (:mod:`openral_nodes.trajectory_action`), which shares
  the follower and its rules with the topic;
- ``/openral/estop`` and ``/openral/release_estop`` (``std_srvs/Trigger``); the E-stop also
  aborts a trajectory;
- ``/openral/reset`` (``std_srvs/Trigger``): the scene back to its seed and start pose,
  carried out by the control loop's next tick; the answer says what was reset.

The three services run on a thread of their own (:mod:`openral_nodes.safety_services`).
Every refusal is a warning naming the topic and the reason, throttled in the log, and
changes nothing; an accepted trajectory is logged at debug level only.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

import numpy as np
from openral_bridge.control_loop import ControlLoop, ResetFailed
from openral_bridge.joint_path import PathRefused
from openral_bridge.joint_state_publisher import sim_stamp
from openral_bridge.topics import (
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_REFUSED,
    JOINT_TRAJECTORY_STATE,
    JTC_JOINT_TRAJECTORY,
    JTC_NAME,
    RELEASE_ESTOP,
    RESET,
    SAFE_ACTION,
    TopicInfo,
)
from openral_bridge.trajectory_follower import DesiredPoint
from openral_core.loaded import LoadedRobot
from openral_core.models import TrajectoryRules
from openral_hal.errors import EStopLatched, HalError
from openral_hal.protocol import ActionScreen, RobotHal
from openral_mujoco.action import validated_action
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from trajectory_msgs.msg import JointTrajectory

from openral_nodes.control_surface import ControlSurface
from openral_nodes.safety_services import SafetyServices
from openral_nodes.trajectory_action import TrajectoryAction
from openral_nodes.trajectory_request import request_from_msg
from openral_nodes.trajectory_wire import trajectory_from_wire

if TYPE_CHECKING:
    from openral_bridge.joint_state_publisher import JointStatePublisher
    from rclpy.node import Node

Entity = tuple[str, Any]
"""(``publisher`` | ``subscription`` | ``service``, the rclpy entity)."""
TOPIC_SOURCE = JOINT_TRAJECTORY
"""How a path from the topic is named in messages (``replaced by /openral/joint_trajectory``)."""


class CommandInterfaces:
    """The command topics and services of one active manifest node (see the module doc)."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        lock: threading.Lock,
        loop: ControlLoop | None,
        *,
        warn_every_s: float,
        rules: TrajectoryRules | None = None,
        robot: LoadedRobot | None = None,
    ) -> None:
        """Nothing is created until :meth:`create`.

        Args:
            node: The node that owns the entities and logs.
            hal: The connected HAL.
            lock: The HAL's lock.
            loop: The control loop of a simulated HAL (None for a real one).
            warn_every_s: At most one warning per this long for a stream of refusals [s].
            rules: The robot's trajectory rules (default: the schema's defaults).
            robot: The loaded robot (its gripper for the gripper action).
        """
        self.node = node
        self.hal = hal
        self.lock = lock
        self.loop = loop
        self.warn_every_s = warn_every_s
        self.accepted = 0
        """Valid actions taken (handed to the control loop, or to a real HAL)."""
        self.refused = 0
        """Actions refused."""
        self.trajectories_accepted = 0
        self.trajectories_refused = 0
        self.rules = rules or TrajectoryRules()
        self.action: TrajectoryAction | None = None
        """The FollowJointTrajectory action while created (None: no trajectories here)."""
        self.surface = ControlSurface(node, hal, lock, loop, robot, self._publish_refused)
        """The controllers at ros2_control's names (:mod:`openral_nodes.control_surface`)."""
        self._safety = SafetyServices(node.context, node.get_name(), node.get_namespace())
        self._state_pub: Any = None
        self._refused_pub: Any = None

    def create(self, states: JointStatePublisher | None = None) -> list[Entity]:
        """Create the subscriptions, the publishers, the actions, the controller manager
        (``states``: the joint state broadcaster's publisher) and the safety services."""
        node = self.node
        self._state_pub = node.create_publisher(JointState, JOINT_TRAJECTORY_STATE, 10)
        self._refused_pub = node.create_publisher(String, JOINT_TRAJECTORY_REFUSED, 10)
        entities: list[Entity] = [
            ("publisher", self._state_pub),
            ("publisher", self._refused_pub),
            (
                "subscription",
                node.create_subscription(Float64MultiArray, SAFE_ACTION, self._on_action, 10),
            ),
            *(
                (
                    "subscription",
                    node.create_subscription(
                        JointTrajectory, topic, self._on_trajectory, 10, raw=True
                    ),
                )
                for topic in (JOINT_TRAJECTORY, JTC_JOINT_TRAJECTORY)
            ),
        ]
        loop = self.loop
        if loop is not None:
            loop.on_sample = self._publish_desired
        if loop is not None and loop.follower is not None:
            action = TrajectoryAction(
                node,
                self.hal,
                self.lock,
                loop,
                loop.follower,
                self.rules,
                on_refused=self._publish_refused,
                active=self.surface.trajectories_active,
            )
            action.create()
            self.action = action
        entities += self.surface.create(states, self.action)
        self._safety.start(self._on_estop, self._on_release_estop, self._on_reset)
        return entities

    def destroy(self) -> None:
        """Stop the safety thread and the action (the node removes the other entities)."""
        self._safety.stop()
        self.surface.destroy()
        if self.action is not None:
            self.action.destroy()
            self.action = None

    @property
    def follows_trajectories(self) -> bool:
        """True when ``/openral/joint_trajectory`` is followed (a simulated HAL whose
        action slots are the manifest joints)."""
        return self.loop is not None and self.loop.follower is not None

    def topics(self) -> list[TopicInfo]:
        """The trajectory state topic (published once per tick while a trajectory runs) and
        the refusals topic."""
        rate = 1.0 / self.loop.period_s if self.loop is not None else None
        return [
            TopicInfo(JOINT_TRAJECTORY_STATE, "sensor_msgs/msg/JointState", rate, "while moving"),
            TopicInfo(JOINT_TRAJECTORY_REFUSED, "std_msgs/msg/String", None, "on a refusal"),
            *self.surface.topics(),
        ]

    # -- topics ----------------------------------------------------------------------------

    def _on_action(self, msg: Any) -> None:
        hal, loop = self.hal, self.loop
        try:
            values = validated_action(np.asarray(msg.data, dtype=np.float64), hal.action_names)
            if isinstance(hal, ActionScreen):  # refused now, not at the next tick
                hal.screen_action(values)
            if loop is None:
                with self.lock:
                    hal.send_action(values)
            elif hal.estopped:
                raise EStopLatched()
            elif loop.offer(values):
                self._log().info("joint trajectory pre-empted by a safe_action")
        except HalError as error:
            self.refused += 1
            self._warn(f"{SAFE_ACTION}: action refused: {error}")
            return
        self.accepted += 1

    def _on_trajectory(self, data: bytes) -> None:
        loop = self.loop
        try:
            follower = loop.follower if loop is not None else None
            if loop is None or follower is None:
                raise PathRefused(self._why_no_trajectories())
            if self.hal.estopped:
                raise PathRefused("the E-stop is latched")
            if not self.surface.trajectories_active():
                raise PathRefused(f"the {JTC_NAME} is inactive (switch_controller activates it)")
            msg = trajectory_from_wire(data, len(self.hal.action_names))
            request = request_from_msg(msg, TOPIC_SOURCE)
            with self.lock:
                hold = np.asarray(self.hal.hold_action(), dtype=np.float64)
                state = loop.state
            if state is None or state.sim_time_s is None:
                raise PathRefused("the scene has no simulated time yet")
            path = follower.submit(request, hold, state.sim_time_s, state.positions)
        except PathRefused as error:
            self.trajectories_refused += 1
            self._warn(f"{JOINT_TRAJECTORY}: trajectory refused: {error}")
            self._publish_refused(str(error))
            return
        self.trajectories_accepted += 1
        self._log().debug(
            f"following a joint trajectory over {', '.join(path.names)}: "
            f"{len(path.times_s) - 1} point(s) from t={path.start_s:.3f} s to "
            f"t={path.end_s:.3f} s (simulated)"
        )

    def _publish_refused(self, reason: str) -> None:
        """One refusal's reason on the refusals topic (a topic, an action goal)."""
        if self._refused_pub is not None:
            self._refused_pub.publish(String(data=reason))

    def _publish_desired(self, point: DesiredPoint) -> None:
        """The desired point after a tick that followed a trajectory (loop thread)."""
        msg = JointState(
            name=list(point.names),
            position=point.positions.tolist(),
            velocity=point.velocities.tolist(),
        )
        msg.header.stamp = sim_stamp(self.node, point.time_s)
        self._state_pub.publish(msg)

    # -- services --------------------------------------------------------------------------

    def _on_estop(self, request: Any, response: Any) -> Any:
        with self.lock:  # a tick in progress ends first; none follows
            self.hal.estop()
        follower = self.loop.follower if self.loop is not None else None
        aborted = follower is not None and follower.cancel("the E-stop latched")
        self.surface.stop_goals("the E-stop latched")
        note = "; the joint trajectory is aborted" if aborted else ""
        held = "the arm is held" if self.hal.is_real else "the scene is frozen"
        self._log().warning(f"E-stop latched: actions are refused and {held}{note}")
        response.success, response.message = True, f"E-stop latched{note}"
        return response

    def _on_release_estop(self, request: Any, response: Any) -> Any:
        try:
            with self.lock:
                self.hal.release_estop()
        except HalError as error:  # the HAL refuses (a real robot's readings are stale)
            response.success, response.message = False, str(error)
            self._log().warning(f"{RELEASE_ESTOP}: refused: {error}")
            return response
        self._log().info("E-stop released")
        response.success, response.message = True, "E-stop released"
        return response

    def _on_reset(self, request: Any, response: Any) -> Any:
        if self.loop is None or self.hal.is_real:
            response.success = False
            response.message = (
                "a real robot cannot be reset: it has no scene to put back; move it with an "
                "action or a joint trajectory"
            )
            self._log().warning(f"{RESET}: refused: {response.message}")
            return response
        self.surface.stop_goals("the scene was reset")
        try:
            text = self.loop.reset()
        except ResetFailed as error:
            response.success, response.message = False, str(error)
            self._log().error(f"{RESET}: {error}")
            return response
        self._log().info(f"reset: {text}")
        response.success, response.message = True, text
        return response

    # -- internals -------------------------------------------------------------------------

    def _why_no_trajectories(self) -> str:
        if self.loop is None:
            return "this HAL has no control loop to follow trajectories with; send safe_action"
        names = self.hal.action_names
        return (
            f"this scene's action is its controller's ({len(names)} slots: "
            f"{', '.join(names[:3])}…), not the manifest's joints; joint trajectories need a "
            "native scene"
        )

    def _warn(self, text: str) -> None:
        self._log().warning(text, throttle_duration_sec=self.warn_every_s)

    def _log(self) -> Any:
        return self.node.get_logger()  # type: ignore[no-untyped-call]
