"""RangeBridge: the depth cameras and lidars of a native scene on ROS.

For each depth sensor the scene serves (:mod:`openral_sim.range_sensors`), at the sensor's
manifest ``rate_hz``:

- ``/openral/cameras/<name>/depth``: ``sensor_msgs/Image``, ``32FC1``, metres along the
  optical axis, NaN where nothing is within ``range_m`` (REP 118), frame ``frame_id``;
- ``/openral/cameras/<name>/camera_info``: the pinhole it was rendered with;
- ``/openral/cameras/<name>/points``: ``sensor_msgs/PointCloud2`` (float32 x, y, z [m])
  in the robot's base frame, without the robot (segmentation, and a margin of 1 cm plus a
  pixel around what the camera sees of it) and without anything out of range.

The base frame is the robot's (``FrameNames.base``: the manifest's ``mobile_base.base_frame``,
the cloud moved by the static offset of the base's root body,
``BaseDrive.root_in_base_frame``; else ``frames.base``, at the robot's root body).

A depth frame is rendered, and its cloud built, on a thread of the sensor's own
(:class:`~openral_bridge.frame_renderer.FrameRenderer`, from a snapshot taken between two
control ticks), never on the control path; a frame due while the previous one is in
flight is skipped. For each lidar, at its ``rate_hz``, one ray cast of the live state on
the pacer's thread (0.1 ms for 1024 rays) is published as ``sensor_msgs/LaserScan`` on
``/scan`` (``/scan/<name>`` when the robot has more than one), frame ``frame_id``,
REP 117 ranges. Every message is stamped with the simulated time of the state it shows.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
from openral_sim.depth_cloud import DepthFrame
from openral_sim.native_scene import NativeScene

from openral_bridge import ros_messages
from openral_bridge.frame_renderer import FrameRenderer
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
    """Depth, cloud and scan publishers of one native scene on one node."""

    def __init__(self, node: Node, scene: NativeScene, lock: threading.Lock) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the publishers.
            scene: The connected native scene (its live data is read holding ``lock``).
            lock: The HAL's lock.
        """
        self.node, self.scene, self.lock = node, scene, lock
        self.base_frame = scene.robot.tables.frames.base
        self.base_offset = np.zeros(3, dtype=np.float32)
        if scene.base is not None:
            self.base_offset = np.asarray(scene.base.root_in_base_frame, dtype=np.float32)
        self._streams: dict[str, _Stream] = {}
        self._pacer: Pacer | None = None

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
        sensors = self.scene.range_sensors
        for name in sensors.depth:
            self._streams[name] = self._depth_stream(name)
        for name in sensors.lidars:
            self._streams[name] = self._scan_stream(name, only=len(sensors.lidars) == 1)
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

        camera = self.scene.range_sensors.depth[name]
        topics = {
            "depth": (depth_image(name), Image),
            "info": (camera_info(name), CameraInfo),
            "points": (depth_points(name), PointCloud2),
        }
        publishers = {
            key: self.node.create_publisher(kind, topic, QUEUE_DEPTH)
            for key, (topic, kind) in topics.items()
        }
        rate = float(camera.sensor.rate_hz)
        stream = _Stream(rate, publishers)
        stream.topics = [
            TopicInfo(t, f"sensor_msgs/msg/{k.__name__}", rate) for t, k in topics.values()
        ]
        model, live = self.scene.mujoco_handles()
        stream.frames = FrameRenderer(
            model,
            live,
            (name,),
            (camera.height, camera.width),
            lambda renderer, data, sensor: camera.frame(renderer, data),
            self._publish_depth,
            name="openral-depth",
        )
        stream.frames.start()
        return stream

    def _publish_depth(self, name: str, frame: DepthFrame, sim_time_s: float) -> None:
        """Publish one depth frame: image, camera info, cloud (render thread)."""
        stream, camera = self._streams.get(name), self.scene.range_sensors.depth[name]
        if stream is None:
            return
        stamp = ros_messages.stamp(sim_time_s)
        frame_id = camera.sensor.frame_id
        height, width = frame.depth_m.shape
        stream.publishers["depth"].publish(ros_messages.image_msg(frame.depth_m, stamp, frame_id))
        info = ros_messages.camera_info_msg(width, height, camera.fovy_deg, stamp, frame_id)
        stream.publishers["info"].publish(info)
        points = frame.points + self.base_offset
        stream.publishers["points"].publish(
            ros_messages.point_cloud_msg(points, stamp, self.base_frame)
        )
        stream.published += 1

    # -- lidar -------------------------------------------------------------------------------

    def _scan_stream(self, name: str, *, only: bool) -> _Stream:
        from sensor_msgs.msg import LaserScan

        scanner = self.scene.range_sensors.lidars[name]
        topic = scan(name, only)
        rate = float(scanner.sensor.rate_hz)
        stream = _Stream(rate, {"scan": self.node.create_publisher(LaserScan, topic, QUEUE_DEPTH)})
        stream.topics = [TopicInfo(topic, "sensor_msgs/msg/LaserScan", rate)]
        return stream

    def _publish_scan(self, name: str) -> None:
        """Cast and publish one scan of the live state (pacer thread)."""
        stream = self._streams[name]
        scanner = self.scene.range_sensors.lidars[name]
        with self.lock:
            ranges = self.scene.range_sensors.scan(name, self.scene.data)
            sim_time_s = float(self.scene.data.time)
        msg = ros_messages.laser_scan_msg(
            ranges,
            angle_range_rad=(scanner.angle_min, scanner.angle_max),
            range_m=(scanner.range_min, scanner.range_max),
            scan_time_s=1.0 / stream.rate_hz,
            stamp_msg=ros_messages.stamp(sim_time_s),
            frame_id=scanner.sensor.frame_id,
        )
        stream.publishers["scan"].publish(msg)
        stream.published += 1

    # -- both --------------------------------------------------------------------------------

    def _due(self, name: str, wait_s: float = 0.0) -> None:
        """A sensor's job: request a depth frame, or cast and publish a scan."""
        frames = self._streams[name].frames
        if frames is None:
            self._publish_scan(name)
            return
        if frames.error is not None:  # as a camera does: said once, its job ends
            stream = self._streams[name]
            if self._pacer is not None and stream.job is not None:
                self._pacer.cancel(stream.job)
                stream.job = None
            self._log().error(
                f"depth sensor {name} stopped rendering ({type(frames.error).__name__}: "
                f"{frames.error}); the robot keeps running without its depth"
            )
            return
        with self.lock:
            frames.request(name, wait_s=wait_s)

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]
