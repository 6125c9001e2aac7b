"""EeBridge: deploy sim's end-effector interface, for a robot with a tool centre point.

- ``/openral/ee_target`` (``geometry_msgs/PoseStamped``): where the TCP should go, in the
  robot's base frame (``header.frame_id`` must name it; the stamp is not used). The control
  loop follows it from its next tick (:mod:`openral_bridge.ee_target`: the env's ``ee_pose``
  mode, one IK step per control period) until a ``safe_action``, a joint trajectory, the
  E-stop or a reset ends it; a newer target replaces it. A target in another frame, with a
  non-finite value or a zero quaternion, or sent while the E-stop is latched is refused:
  a throttled warning and the reason on ``/openral/ee_target/refused`` (``std_msgs/String``),
  and nothing changes.
- ``/openral/ee_target/state`` (``sensor_msgs/JointState``): the arm's targets of each
  tick's IK step (and their speed), stamped in simulated time, while a target is followed.
- ``/openral/tcp_pose`` (``geometry_msgs/PoseStamped``): the TCP's pose in the base frame,
  stamped in simulated time, after every control tick (or at a slower joint-state rate).

Every call into the HAL holds ``lock`` (the node's HAL lock).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from openral_hal.errors import HalError
from openral_hal.sim_attached import SimAttachedHAL
from openral_sim.ee_modes import EeCommand

from openral_bridge import ros_messages
from openral_bridge.control_loop import ControlLoop
from openral_bridge.ee_target import EeTargetFollower, EeTargetRefused, checked_pose
from openral_bridge.paced_publishers import Cadence
from openral_bridge.pacer import Pacer
from openral_bridge.topics import (
    EE_TARGET,
    EE_TARGET_REFUSED,
    EE_TARGET_STATE,
    TCP_POSE,
    TopicInfo,
)
from openral_bridge.trajectory_follower import DesiredPoint

if TYPE_CHECKING:
    from rclpy.node import Node

WARN_EVERY_S = 2.0
"""At most one warning per this many seconds for a stream of refused targets [s]."""


def pose_msg(values: Any, frame_id: str, sim_time_s: float) -> Any:
    """``geometry_msgs/PoseStamped`` of a pose as 7 values (position [m], w, x, y, z)."""
    from geometry_msgs.msg import PoseStamped

    msg = PoseStamped()
    msg.header.stamp = ros_messages.stamp(sim_time_s)
    msg.header.frame_id = frame_id
    position, orientation = msg.pose.position, msg.pose.orientation
    position.x, position.y, position.z = (float(v) for v in values[:3])
    orientation.w, orientation.x, orientation.y, orientation.z = (float(v) for v in values[3:7])
    return msg


class EeBridge:
    """The end-effector target, its state and the TCP pose of one simulated HAL."""

    def __init__(
        self,
        node: Node,
        hal: SimAttachedHAL,
        ee: EeCommand,
        loop: ControlLoop,
        rate_hz: float,
        lock: threading.Lock,
    ) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the entities and logs.
            hal: The connected simulated HAL.
            ee: The HAL's end-effector command (:func:`openral_hal.tool_centre.ee_command`).
            loop: The HAL's control loop; it follows the target.
            rate_hz: ``/openral/tcp_pose`` publish rate [Hz].
            lock: The HAL's lock.
        """
        self.node, self.hal, self.ee, self.loop = node, hal, ee, loop
        self.rate_hz, self.lock = rate_hz, lock
        self.follower = EeTargetFollower(hal, ee)
        self.refused = 0
        self._entities: list[tuple[str, Any]] = []
        self._cadence = Cadence()

    def topics(self) -> list[TopicInfo]:
        """What the bridge publishes (the target topic is subscribed, not listed)."""
        if not self._entities:
            return []
        tick_hz = 1.0 / self.loop.period_s
        return [
            TopicInfo(TCP_POSE, "geometry_msgs/msg/PoseStamped", self.rate_hz),
            TopicInfo(EE_TARGET_STATE, "sensor_msgs/msg/JointState", tick_hz, "while moving"),
            TopicInfo(EE_TARGET_REFUSED, "std_msgs/msg/String", None, "on a refusal"),
        ]

    def start(self, pacer: Pacer) -> None:
        """Create the entities, wire the follower into the loop, publish the TCP pose now
        and then as a job of ``pacer``."""
        from geometry_msgs.msg import PoseStamped
        from sensor_msgs.msg import JointState
        from std_msgs.msg import String

        self.stop()
        node = self.node
        self._tcp = node.create_publisher(PoseStamped, TCP_POSE, 10)
        self._state = node.create_publisher(JointState, EE_TARGET_STATE, 10)
        self._refused = node.create_publisher(String, EE_TARGET_REFUSED, 10)
        target = node.create_subscription(PoseStamped, EE_TARGET, self.on_target, 10)
        self._entities = [
            ("publisher", self._tcp),
            ("publisher", self._state),
            ("publisher", self._refused),
            ("subscription", target),
        ]
        self.loop.ee, self.loop.on_ee_sample = self.follower, self.publish_state
        self.publish_tcp()
        self.rate_hz = self._cadence.start(
            pacer, self.rate_hz, self.publish_tcp, TCP_POSE, self.loop
        )

    def stop(self) -> None:
        """Unwire the follower, cancel the job and destroy the entities (idempotent)."""
        if self.loop.ee is self.follower:
            self.follower.cancel("the bridge stopped")
            self.loop.ee, self.loop.on_ee_sample = None, None
        self._cadence.stop()
        for kind, entity in reversed(self._entities):
            if kind == "publisher":
                self.node.destroy_publisher(entity)
            else:
                self.node.destroy_subscription(entity)
        self._entities = []

    def on_target(self, msg: Any) -> None:
        """Take one target (see the module doc); never raises."""
        try:
            frame = str(msg.header.frame_id)
            base = self.follower.base_frame
            if frame != base:
                raise EeTargetRefused(
                    f"header.frame_id is {frame!r}; expected the base frame {base!r}"
                )
            position, orientation = msg.pose.position, msg.pose.orientation
            pose = checked_pose(
                (position.x, position.y, position.z),
                (orientation.w, orientation.x, orientation.y, orientation.z),
            )
            if self.hal.estopped:
                raise EeTargetRefused("the E-stop is latched")
            if self.loop.follower is not None:
                self.loop.follower.cancel(f"a target on {EE_TARGET} pre-empted it")
            self.follower.submit(pose)
        except (EeTargetRefused, HalError) as error:
            self.refused += 1
            self._log().warning(
                f"{EE_TARGET}: target refused: {error}", throttle_duration_sec=WARN_EVERY_S
            )
            from std_msgs.msg import String

            self._refused.publish(String(data=str(error)))

    def publish_tcp(self) -> None:
        """Publish ``/openral/tcp_pose`` once (the TCP now)."""
        with self.lock:
            handles = self.hal.mujoco_handles()
            if handles is None:
                return
            values = self.ee.tcp_vector(handles[1])
            sim_time_s = float(handles[1].time)
        self._tcp.publish(pose_msg(values, self.follower.base_frame, sim_time_s))

    def publish_state(self, point: DesiredPoint) -> None:
        """The arm's targets after a tick towards the target (loop thread)."""
        stamp = ros_messages.stamp(point.time_s)
        names, positions, speeds = point.names, point.positions, point.velocities
        msg = ros_messages.joint_state_msg(names, positions, speeds, positions[:0], stamp)
        self._state.publish(msg)

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]
