"""RangeBridge: depth cameras and lidars on ROS, from any HAL that serves them.

The bridge depends only on :class:`~openral_sim.sensor_sources.DepthSource` and
:class:`~openral_sim.sensor_sources.LidarSource` (a native scene's HAL, a real driver's).
For each depth sensor served, at its rate (:func:`~openral_sim.sensor_schedule.sensor_rates`):

- ``/openral/cameras/<name>/depth``: ``sensor_msgs/Image``, ``32FC1``, metres along the
  optical axis, NaN where nothing is within ``range_m`` (REP 118), frame ``frame_id``;
- ``/openral/cameras/<name>/camera_info``: the pinhole it was rendered with;
- ``/openral/cameras/<name>/points``: ``sensor_msgs/PointCloud2`` (float32 x, y, z [m])
  in the frame the source names (``DepthSpec.cloud_frame``: a native scene's clouds are in
  the robot's base frame, without the robot and without anything out of range).

A depth frame is developed, and its cloud built, on a thread of the sensor's own
(:class:`~openral_bridge.frame_renderer.FrameRenderer`, from a snapshot taken between two
control ticks), never on the control path; a frame due while the previous one is in
flight is skipped. For each lidar, at its rate, one scan read on the pacer's thread
holding the HAL's lock (a native scene's ray cast: 0.1 ms for 1024 rays) is published as
``sensor_msgs/LaserScan`` on ``/scan`` (``/scan/<name>`` when the robot has more than
one), frame ``frame_id``, REP 117 ranges. Every message is stamped with the time of the
state it shows.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Any

from openral_sim.depth_cloud import DepthFrame
from openral_sim.sensor_sources import DepthSource, LidarSource

from openral_bridge import ros_messages
from openral_bridge.frame_renderer import FrameRenderer, SnapshotGate
from openral_bridge.pacer import PacedJob, Pacer
from openral_bridge.sim_sensor_bridge import NOW_WAIT_S
from openral_bridge.topics import TopicInfo, camera_info, depth_image, depth_points, scan

if TYPE_CHECKING:
    from rclpy.node import Node

QUEUE_DEPTH = 5


@dataclass
class _Stream:
    """One sensor's publishers, job and (depth) renderer."""

    rate_hz: float
    publishers: dict[str, Any]
    job: PacedJob | None = None
    frames: FrameRenderer[DepthFrame] | None = None
    published: int = 0
    topics: list[TopicInfo] = field(default_factory=list)


class RangeBridge:
    """Depth, cloud and scan publishers of one HAL on one node."""

    def __init__(
        self,
        node: Node,
        depth: DepthSource | None,
        lidar: LidarSource | None,
        lock: threading.Lock,
        rates_hz: Mapping[str, float],
    ) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the publishers.
            depth: What serves the depth sensors (None: none).
            lidar: What serves the lidars (None: none).
            lock: The HAL's lock (held while a snapshot or a scan is taken).
            rates_hz: Each sensor's rate [Hz] (a sensor missing here keeps its manifest's).
        """
        self.node, self.lock = node, lock
        self.depth = dict(depth.depth_sensors()) if depth is not None else {}
        self.lidars = dict(lidar.lidar_sensors()) if lidar is not None else {}
        self._depth_source, self._lidar_source = depth, lidar
        self.rates_hz = dict(rates_hz)
        self._streams: dict[str, _Stream] = {}
        self._pacer: Pacer | None = None
        self.gate: SnapshotGate | None = None
        """When a paced snapshot or scan may be taken (None: whenever it is due)."""

    def topics(self) -> list[TopicInfo]:
        """What the bridge publishes now."""
        return [topic for stream in self._streams.values() for topic in stream.topics]

    def published_counts(self) -> dict[str, int]:
        """Frames or scans published so far, by sensor."""
        return {name: stream.published for name, stream in self._streams.items()}

    def start(self, pacer: Pacer) -> None:
        """Create every publisher, start the depth threads and schedule each sensor's job
        on ``pacer``; each sensor publishes once now."""
        self.stop()
        self._pacer = pacer
        for name in self.depth:
            self._streams[name] = self._depth_stream(name)
        for name in self.lidars:
            self._streams[name] = self._scan_stream(name, only=len(self.lidars) == 1)
        for name, stream in self._streams.items():
            due = partial(self._due, name)
            stream.job = pacer.every(1.0 / stream.rate_hz, due, f"range {name}")
        self.publish_now()

    def publish_now(self) -> None:
        """A depth frame or scan of every sensor as the scene is now; takes the HAL's lock."""
        for name in self._streams:
            self._due(name, wait_s=NOW_WAIT_S)

    def stop(self) -> None:
        """Cancel the jobs, stop the depth threads and destroy the publishers (idempotent)."""
        for stream in self._streams.values():
            if self._pacer is not None and stream.job is not None:
                self._pacer.cancel(stream.job)
            if stream.frames is not None and not stream.frames.stop():
                self._log().warning("a depth render thread did not stop within its timeout")
            for publisher in stream.publishers.values():
                self.node.destroy_publisher(publisher)
        self._streams.clear()
        self._pacer = None

    # -- depth -------------------------------------------------------------------------------

    def _depth_stream(self, name: str) -> _Stream:
        from sensor_msgs.msg import CameraInfo, Image, PointCloud2

        spec = self.depth[name]
        assert self._depth_source is not None
        topics = {
            "depth": (depth_image(name), Image),
            "info": (camera_info(name), CameraInfo),
            "points": (depth_points(name), PointCloud2),
        }
        publishers = {
            key: self.node.create_publisher(kind, topic, QUEUE_DEPTH)
            for key, (topic, kind) in topics.items()
        }
        rate = self._rate(name, spec.sensor.rate_hz)
        stream = _Stream(rate, publishers)
        stream.topics = [
            TopicInfo(t, f"sensor_msgs/msg/{k.__name__}", rate) for t, k in topics.values()
        ]
        capture = self._depth_source.depth_capture(name)
        stream.frames = FrameRenderer(capture, self._publish_depth, name="openral-depth")
        stream.frames.start()
        return stream

    def _publish_depth(self, name: str, frame: DepthFrame, sim_time_s: float) -> None:
        """Publish one depth frame: image, camera info, cloud (render thread)."""
        stream, spec = self._streams.get(name), self.depth[name]
        if stream is None:
            return
        stamp = ros_messages.stamp(sim_time_s)
        frame_id = spec.sensor.frame_id
        height, width = frame.depth_m.shape
        stream.publishers["depth"].publish(ros_messages.image_msg(frame.depth_m, stamp, frame_id))
        info = ros_messages.camera_info_msg(width, height, spec.fovy_deg, stamp, frame_id)
        stream.publishers["info"].publish(info)
        stream.publishers["points"].publish(
            ros_messages.point_cloud_msg(frame.points, stamp, spec.cloud_frame)
        )
        stream.published += 1

    # -- lidar -------------------------------------------------------------------------------

    def _scan_stream(self, name: str, *, only: bool) -> _Stream:
        from sensor_msgs.msg import LaserScan

        topic = scan(name, only)
        rate = self._rate(name, self.lidars[name].sensor.rate_hz)
        stream = _Stream(rate, {"scan": self.node.create_publisher(LaserScan, topic, QUEUE_DEPTH)})
        stream.topics = [TopicInfo(topic, "sensor_msgs/msg/LaserScan", rate)]
        return stream

    def _publish_scan(self, name: str, gate: SnapshotGate | None) -> float | None:
        """Cast and publish one scan of the live state (pacer thread) once ``gate`` lets it
        (returns the gate's delay [s] instead)."""
        stream, spec = self._streams[name], self.lidars[name]
        assert self._lidar_source is not None
        with self.lock:
            if gate is not None and (delay_s := gate()) > 0.0:
                return delay_s
            reading = self._lidar_source.scan(name)
        msg = ros_messages.laser_scan_msg(
            reading.ranges,
            angle_range_rad=(spec.angle_min_rad, spec.angle_max_rad),
            range_m=(spec.range_min_m, spec.range_max_m),
            scan_time_s=1.0 / stream.rate_hz,
            stamp_msg=ros_messages.stamp(reading.sim_time_s),
            frame_id=spec.sensor.frame_id,
        )
        stream.publishers["scan"].publish(msg)
        stream.published += 1
        return None

    # -- both --------------------------------------------------------------------------------

    def _due(self, name: str, wait_s: float = 0.0) -> float | None:
        """A sensor's job: request a depth frame, or cast and publish a scan; returns
        :data:`~openral_bridge.frame_renderer.RETRY_S` when the previous depth frame is
        still in flight, or the :attr:`gate`'s delay (the pacer asks again that much
        later), else None."""
        frames, gate = self._streams[name].frames, self.gate if wait_s == 0.0 else None
        if frames is None:
            return self._publish_scan(name, gate)
        if frames.error is not None:  # as a camera does: said once, its job ends
            stream = self._streams[name]
            if self._pacer is not None and stream.job is not None:
                self._pacer.cancel(stream.job)
                stream.job = None
            self._log().error(
                f"depth sensor {name} stopped rendering ({type(frames.error).__name__}: "
                f"{frames.error}); the robot keeps running without its depth"
            )
            return None
        return frames.request_or_retry(name, self.lock, wait_s=wait_s, gate=gate)

    def _rate(self, name: str, manifest_hz: float) -> float:
        return float(self.rates_hz.get(name, manifest_hz))

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]
