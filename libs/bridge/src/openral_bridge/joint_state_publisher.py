"""JointStatePublisher: ``/joint_states`` of a HAL at a fixed rate, from a pacer job.

Each message carries every manifest joint (name, position, velocity, effort) of one
:meth:`RobotHal.read_state`, stamped in simulated time (the node clock for a HAL without
one). A robot with a mobile base adds its drive joints after them, under their MJCF names
(``BaseDrive.joint_state``: the x and y slides [m] and the yaw hinge [rad]), so the scene's
base pose is on ``/joint_states`` too; the action contract has no base slots.
The state is read holding the HAL's lock, so it is never read in the middle of a
control tick; the message is built and published after the lock is released.

A simulated scene changes only when the control loop ticks, and the loop reads the state
right after each tick (:attr:`~openral_bridge.control_loop.ControlLoop.state`). Given that
sample (``latest``), the publisher builds one message per tick and publishes it until the
next: at 50 Hz over a 20 Hz loop each state goes out 2-3 times, exactly as reading the
HAL each time would send it, for a fraction of the CPU.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from openral_hal.protocol import RobotHal
from openral_mujoco.state import JointStateSample
from openral_sim.base_drive import BaseDrive
from sensor_msgs.msg import JointState

from openral_bridge import ros_messages
from openral_bridge.pacer import PacedJob, Pacer
from openral_bridge.topics import JOINT_STATES

if TYPE_CHECKING:
    from rclpy.node import Node

QUEUE_DEPTH = 10
"""Queue of the ``/joint_states`` publisher."""
LatestFn = Callable[[], JointStateSample | None]
"""The state as of the last control tick, or None when the HAL must be read."""


def sim_stamp(node: Node, sim_time_s: float | None) -> Any:
    """Simulated time [s] as a header stamp; the node clock's time for None."""
    if sim_time_s is None:
        return node.get_clock().now().to_msg()
    return ros_messages.stamp(sim_time_s)


class JointStatePublisher:
    """Publishes a HAL's joint state once at :meth:`start`, then at ``rate_hz`` on a pacer."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        lock: threading.Lock,
        rate_hz: float,
        *,
        latest: LatestFn | None = None,
        base: BaseDrive | None = None,
    ) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the publisher.
            hal: A connected HAL.
            lock: The HAL's lock, held while the state is read.
            rate_hz: Publish rate [Hz].
            latest: The state as of the last control tick (see the module doc); None, or
                a None from it, reads the HAL.
            base: The robot's mobile base, whose drive joints are appended (None: none).
        """
        self.node = node
        self.hal = hal
        self.lock = lock
        self.rate_hz = float(rate_hz)
        self.latest = latest
        self.base = base
        self.published = 0
        """Messages published since :meth:`start`."""
        self._publisher: Any = None
        self._job: tuple[Pacer, PacedJob] | None = None
        self._message: tuple[JointStateSample, Any] | None = None

    def start(self, pacer: Pacer) -> None:
        """Create the publisher, publish once, then once per period on ``pacer``."""
        self.stop()
        self._publisher = self.node.create_publisher(JointState, JOINT_STATES, QUEUE_DEPTH)
        self.published = 0
        self.publish()
        self._job = (pacer, pacer.every(1.0 / self.rate_hz, self.publish, "joint_states"))

    def stop(self) -> None:
        """Unschedule the job and destroy the publisher (idempotent)."""
        if self._job is not None:
            pacer, job = self._job
            self._job = None
            pacer.cancel(job)
        if self._publisher is not None:
            publisher, self._publisher = self._publisher, None
            self.node.destroy_publisher(publisher)
        self._message = None

    def publish(self) -> None:
        """Publish the state as of now."""
        publisher = self._publisher
        if publisher is not None:
            publisher.publish(self._message_of(self._sample()))
            self.published += 1

    def _sample(self) -> JointStateSample:
        sample = self.latest() if self.latest is not None else None
        if sample is None:
            with self.lock:
                sample = self.hal.read_state()
        return sample

    def _message_of(self, sample: JointStateSample) -> Any:
        """The message of ``sample``, built once per sample."""
        if self._message is not None and self._message[0] is sample:
            return self._message[1]
        stamp = sim_stamp(self.node, sample.sim_time_s)
        names, positions = sample.names, sample.positions
        velocities, efforts = sample.velocities, sample.efforts
        if self.base is not None:  # read on the pacer's thread, which also ticks: same state
            with self.lock:
                base = self.base.joint_state()
            names += base.names
            positions = np.concatenate([positions, base.positions])
            velocities = np.concatenate([velocities, base.velocities])
            efforts = np.concatenate([efforts, base.efforts])
        message = ros_messages.joint_state_msg(names, positions, velocities, efforts, stamp)
        self._message = (sample, message)
        return message
