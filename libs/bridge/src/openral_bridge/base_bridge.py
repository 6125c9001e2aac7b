"""BaseBridge: ``/cmd_vel`` in and ``/odom`` out for a robot with a mobile base.

- ``/cmd_vel`` (``geometry_msgs/Twist``, base frame): ``linear.x``, ``linear.y`` [m/s] and
  ``angular.z`` [rad/s] go to :meth:`MobileBaseHal.command_base`, which clamps them to the
  manifest's limits and keeps them until the next command or ``command_timeout_s`` of
  simulated time (then the base ramps to a stop). A planar base cannot follow
  ``linear.z``, ``angular.x`` or ``angular.y``; a command with any of them non-zero is
  taken without them, with a throttled warning. A non-finite value, or a command while the
  E-stop is latched (the base is already halted), is refused with a throttled warning and
  changes nothing.
- ``/odom`` (``nav_msgs/Odometry``) after every control tick (or at a slower joint-state
  rate, on the node's :class:`~openral_bridge.pacer.Pacer`): header frame ``odom_frame``,
  child frame ``base_frame`` (both from the manifest), pose in the odometry frame (where
  the base frame was at the last reset, REP 105), twist in the base frame, stamped in
  simulated time. Covariances follow the drive (a holonomic planar base): the simulation
  knows the pose exactly, so the dims the base moves in (x, y, yaw; vx, vy, wz) carry
  :data:`PLANAR_VARIANCE` (never zero: a filter fusing it must not meet a singular matrix),
  and the dims it cannot move in (z, roll, pitch and their rates) :data:`FIXED_VARIANCE`.

Every call into the HAL is made holding ``lock`` (the node's lock around its HAL), so it
never overlaps a control tick running on the pacer's thread.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from openral_hal.errors import HalError
from openral_hal.protocol import MobileBaseHal
from openral_sim.base_drive import BaseOdometry

from openral_bridge import ros_messages
from openral_bridge.paced_publishers import Cadence
from openral_bridge.pacer import Pacer
from openral_bridge.topics import CMD_VEL, ODOM, TopicInfo

if TYPE_CHECKING:
    from rclpy.node import Node

    from openral_bridge.control_loop import ControlLoop

PLANAR_VARIANCE = 1e-6
"""Variance of x, y [m²], yaw [rad²] and of vx, vy, wz: a 1 mm / 1 mrad floor."""
FIXED_VARIANCE = 1e-9
"""Variance of z, roll, pitch and their rates: held by the floor, known exactly."""
_PLANAR = (0, 7, 35)
"""Diagonal indices of x, y and yaw (z-rotation) in a 6x6 row-major covariance."""
COVARIANCE = [
    (PLANAR_VARIANCE if i in _PLANAR else FIXED_VARIANCE) if i % 7 == 0 else 0.0 for i in range(36)
]
"""The pose and twist covariance of every ``/odom`` message (see the module doc)."""
WARN_EVERY_S = 2.0
"""At most one warning per this many seconds for a stream of refused commands [s]."""


def odometry_msg(odometry: BaseOdometry) -> Any:
    """``nav_msgs/Odometry`` of the base's odometry (see the module doc)."""
    from nav_msgs.msg import Odometry

    msg = Odometry()
    msg.header.stamp = ros_messages.stamp(odometry.sim_time_s)
    msg.header.frame_id = odometry.odom_frame
    msg.child_frame_id = odometry.base_frame
    pose = msg.pose.pose
    pose.position.x, pose.position.y = odometry.x_m, odometry.y_m
    pose.orientation.z = math.sin(odometry.yaw_rad / 2)
    pose.orientation.w = math.cos(odometry.yaw_rad / 2)
    twist = msg.twist.twist
    twist.linear.x, twist.linear.y = odometry.vx_m_s, odometry.vy_m_s
    twist.angular.z = odometry.wz_rad_s
    msg.pose.covariance = msg.twist.covariance = COVARIANCE
    return msg


class BaseBridge:
    """``/cmd_vel`` subscription, ``/odom`` publisher and job of one mobile-base HAL."""

    def __init__(
        self,
        node: Node,
        hal: MobileBaseHal,
        rate_hz: float,
        lock: threading.Lock,
        loop: ControlLoop | None = None,
    ) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the subscription and the publisher.
            hal: A connected HAL whose ``base`` is not None.
            rate_hz: ``/odom`` publish rate [Hz].
            lock: The HAL's lock, held for every call into it.
            loop: The control loop: ``/odom`` goes out after each of its ticks when
                ``rate_hz`` is as fast (each message a new state).
        """
        self.node = node
        self.hal = hal
        self.rate_hz = rate_hz
        self.lock = lock
        self.loop = loop
        self.accepted = 0
        """Velocity commands taken (possibly clamped)."""
        self.refused = 0
        self._entities: list[tuple[str, Any]] = []
        self._cadence = Cadence()

    def topics(self) -> list[TopicInfo]:
        """What the bridge publishes (``/cmd_vel`` is subscribed, not listed)."""
        return [TopicInfo(ODOM, "nav_msgs/msg/Odometry", self.rate_hz)] if self._entities else []

    def start(self, pacer: Pacer) -> None:
        """Advertise ``/odom`` and publish it once now and then as a job of ``pacer``;
        subscribe ``/cmd_vel``."""
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry

        self.stop()
        self._odom = self.node.create_publisher(Odometry, ODOM, 10)
        self._entities = [
            ("publisher", self._odom),
            ("subscription", self.node.create_subscription(Twist, CMD_VEL, self.on_cmd_vel, 10)),
        ]
        self.publish_odometry()
        self.rate_hz = self._cadence.start(
            pacer, self.rate_hz, self.publish_odometry, ODOM, self.loop
        )

    def stop(self) -> None:
        """Cancel the job (it has finished when this returns) and destroy the publisher and
        subscription (idempotent)."""
        self._cadence.stop()
        destroy: dict[str, Callable[[Any], object]] = {
            "publisher": self.node.destroy_publisher,
            "subscription": self.node.destroy_subscription,
        }
        for kind, entity in reversed(self._entities):
            destroy[kind](entity)
        self._entities = []

    def on_cmd_vel(self, msg: Any) -> None:
        """Hand one Twist to the HAL (see the module doc); never raises."""
        ignored = (msg.linear.z, msg.angular.x, msg.angular.y)
        try:
            values = [float(v) for v in (msg.linear.x, msg.linear.y, msg.angular.z)]
            with self.lock:
                self.hal.command_base(*values)
        except HalError as error:
            self.refused += 1
            self._log().warning(f"{CMD_VEL} refused: {error}", throttle_duration_sec=WARN_EVERY_S)
            return
        self.accepted += 1
        if any(v != 0.0 for v in ignored):
            self._log().warning(
                f"{CMD_VEL}: a planar base ignores linear.z, angular.x and angular.y",
                throttle_duration_sec=WARN_EVERY_S,
            )

    def publish_odometry(self) -> None:
        """Publish ``/odom`` once (the base's state now)."""
        with self.lock:
            odometry = self.hal.base_odometry()
        self._odom.publish(odometry_msg(odometry))

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]
