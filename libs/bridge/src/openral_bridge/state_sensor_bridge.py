"""StateSensorBridge: IMU, force-torque and pose sensors on ROS, from any HAL that serves them.

The bridge depends only on :class:`~openral_sim.sensor_sources.StateSensorSource` (a native
scene's HAL reads them from MuJoCo's ``sensordata``; a real driver from its hardware). For
each sensor served:

- ``imu`` → ``sensor_msgs/Imu`` on ``/openral/imu/<name>``: orientation (world frame),
  angular velocity and linear acceleration (gravity included) in the site's frame, header
  frame the sensor's ``frame_id``; the simulation is noise-free and no covariance is
  estimated, so every covariance is all zeros ("unknown", as ``sensor_msgs/Imu`` says);
- ``force_torque`` → ``geometry_msgs/WrenchStamped`` on ``/openral/wrench/<name>``, in the
  site's frame (header frame ``frame_id``);
- ``pose`` → ``geometry_msgs/PoseStamped`` on ``/openral/pose/<name>``, in the world frame
  (header frame: the robot's world frame, ``frames.world``).

Each sensor publishes at its rate from :func:`~openral_sim.sensor_schedule.sensor_rates`
(its ``rate_hz``, capped at the control rate: a reading changes only when the scene steps);
:meth:`StateSensorBridge.topics` reports that rate. Each message is read on the pacer's
thread holding the HAL's lock and stamped with the time of the state it shows.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

from openral_sim.sensor_sources import StateSensorSource
from openral_sim.state_sensors import ImuReading, PoseReading, Reading, WrenchReading

from openral_bridge import ros_messages
from openral_bridge.pacer import PacedJob, Pacer
from openral_bridge.topics import TopicInfo, imu, pose, wrench

if TYPE_CHECKING:
    from rclpy.node import Node

QUEUE_DEPTH = 10


@dataclass
class _Stream:
    topic: TopicInfo
    publisher: Any
    frame_id: str
    job: PacedJob | None = None
    published: int = 0


class StateSensorBridge:
    """Imu, WrenchStamped and PoseStamped publishers of one HAL on one node."""

    def __init__(
        self,
        node: Node,
        source: StateSensorSource,
        lock: threading.Lock,
        rates_hz: Mapping[str, float],
    ) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the publishers.
            source: What serves the sensors (read holding ``lock``).
            lock: The HAL's lock.
            rates_hz: Each sensor's rate [Hz] (a sensor missing here keeps its manifest's).
        """
        self.node, self.source, self.lock = node, source, lock
        self.specs = dict(source.state_sensors())
        self.rates_hz = dict(rates_hz)
        self._streams: dict[str, _Stream] = {}
        self._pacer: Pacer | None = None

    @property
    def served(self) -> frozenset[str]:
        """The sensors this bridge publishes."""
        return frozenset(self.specs)

    def topics(self) -> list[TopicInfo]:
        """What the bridge publishes now, at the rates it publishes at."""
        return [stream.topic for stream in self._streams.values()]

    def published_counts(self) -> dict[str, int]:
        """Messages published so far, by sensor."""
        return {name: stream.published for name, stream in self._streams.items()}

    def start(self, pacer: Pacer) -> None:
        """Create the publishers and schedule each sensor's job; each publishes once now."""
        self.stop()
        self._pacer = pacer
        for name, spec in self.specs.items():
            rate = float(self.rates_hz.get(name, spec.sensor.rate_hz))
            self._streams[name] = self._stream(name, spec.sensor.kind, spec.frame_id, rate)
        for name, stream in self._streams.items():
            assert stream.topic.rate_hz is not None
            job = partial(self._publish, name)
            stream.job = pacer.every(1.0 / stream.topic.rate_hz, job, f"state {name}")
        self.publish_now()

    def publish_now(self) -> None:
        """Every sensor's reading of the scene as it is now; takes the HAL's lock."""
        for name in self._streams:
            self._publish(name)

    def stop(self) -> None:
        """Cancel the jobs and destroy the publishers (idempotent)."""
        for stream in self._streams.values():
            if self._pacer is not None and stream.job is not None:
                self._pacer.cancel(stream.job)
            self.node.destroy_publisher(stream.publisher)
        self._streams.clear()
        self._pacer = None

    def _stream(self, name: str, kind: str, frame_id: str, rate_hz: float) -> _Stream:
        from geometry_msgs.msg import PoseStamped, WrenchStamped
        from sensor_msgs.msg import Imu

        topic, msg_type = {
            "imu": (imu(name), Imu),
            "force_torque": (wrench(name), WrenchStamped),
            "pose": (pose(name), PoseStamped),
        }[kind]
        package = msg_type.__module__.split(".")[0]
        info = TopicInfo(topic, f"{package}/msg/{msg_type.__name__}", rate_hz)
        return _Stream(info, self.node.create_publisher(msg_type, topic, QUEUE_DEPTH), frame_id)

    def _publish(self, name: str) -> None:
        """Read one sensor under the lock and publish its message (pacer thread)."""
        stream = self._streams[name]
        with self.lock:
            reading = self.source.read_sensor(name)
        stream.publisher.publish(_message(reading, stream.frame_id))
        stream.published += 1


def _message(reading: Reading, frame_id: str) -> Any:
    """The ROS message of one reading."""
    from geometry_msgs.msg import PoseStamped, WrenchStamped
    from sensor_msgs.msg import Imu

    msg: Any
    if isinstance(reading, ImuReading):
        msg = Imu()
        _quaternion(msg.orientation, reading.orientation_xyzw)
        _vector(msg.angular_velocity, reading.angular_velocity)
        _vector(msg.linear_acceleration, reading.linear_acceleration)
    elif isinstance(reading, WrenchReading):
        msg = WrenchStamped()
        _vector(msg.wrench.force, reading.force)
        _vector(msg.wrench.torque, reading.torque)
    else:
        assert isinstance(reading, PoseReading)
        msg = PoseStamped()
        _vector(msg.pose.position, reading.position)
        _quaternion(msg.pose.orientation, reading.orientation_xyzw)
    msg.header.stamp = ros_messages.stamp(reading.sim_time_s)
    msg.header.frame_id = frame_id
    return msg


def _vector(target: Any, values: Any) -> None:
    target.x, target.y, target.z = (float(v) for v in values[:3])


def _quaternion(target: Any, xyzw: Any) -> None:
    target.x, target.y, target.z, target.w = (float(v) for v in xyzw[:4])
