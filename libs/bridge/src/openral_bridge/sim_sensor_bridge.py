"""SimSensorBridge: publish what a simulated scene's sensors see.

One bridge serves every robot; what it publishes follows the manifest and what the HAL
can do:

- each manifest RGB sensor the scene renders → ``sensor_msgs/Image`` (rgb8) on
  ``/openral/cameras/<name>/image`` and ``sensor_msgs/CameraInfo`` on
  ``/openral/cameras/<name>/camera_info``, frame id from the manifest, at the rate
  :func:`~openral_sim.sensor_schedule.sensor_rates` gives it (one job per sensor on the
  node's :class:`~openral_bridge.pacer.Pacer`);
- the MuJoCo passive viewer when enabled and a display exists (synced by a pacer job);
- every published frame also to :attr:`SimSensorBridge.on_frame` when set (the browser
  view).

A HAL that is a :class:`~openral_sim.sensor_sources.CameraSource` (a native scene's, or
any driver's) has a camera rendered only when its frame is due, off the control path: its
job (pacer thread, HAL lock held, never mid-tick; with a :attr:`~SimSensorBridge.gate`,
only at a control period's end) takes a snapshot and a
:class:`~openral_bridge.frame_renderer.FrameRenderer` thread develops and publishes it; a
camera still busy with its previous frame is skipped and counted
(:attr:`SimSensorBridge.frames_skipped`). While the bridge serves its cameras the scene's
``reset``/``step`` render nothing. A backend that renders inside its own step (robosuite)
publishes the last observation's frames (``read_images()``) instead, on the pacer's thread.

Header stamps are simulation time (MuJoCo ``data.time``; the node publishes ``/clock``):
a rendered frame carries its snapshot's time, so the stamp says which physics state it
shows; a HAL without simulation time stamps with the node clock. Depth and lidar sensors
are :class:`~openral_bridge.range_bridge.RangeBridge`'s; those it does not serve are
reported, not published.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import DepthSensor, RgbSensor, RobotDescription, SiteSensor
from openral_hal.protocol import CameraHal, MujocoBacked, RobotHal
from openral_mujoco.display import has_display
from openral_sim.sensor_sources import CameraSource, ObservationFrames

from openral_bridge import ros_messages
from openral_bridge.camera_messages import CameraMessages
from openral_bridge.frame_renderer import FrameRenderer, ImageArray, SnapshotGate
from openral_bridge.pacer import PacedJob, Pacer
from openral_bridge.topics import TopicInfo, camera_image, camera_info

if TYPE_CHECKING:
    from rclpy.node import Node

NOW_WAIT_S = 1.0
"""Longest wait of :meth:`SimSensorBridge.publish_now` for a frame still in flight [s]."""
IMAGE_QUEUE_DEPTH = 5
"""Reliable queue of the image publishers: a slow subscriber drops old frames, not new."""


@dataclass
class _Camera:
    """One published RGB sensor: its manifest entry, rate [Hz], messages, publishers."""

    sensor: RgbSensor
    rate_hz: float
    messages: CameraMessages
    image_pub: Any
    info_pub: Any | None
    job: PacedJob | None = None
    published: int = 0


class SimSensorBridge:
    """Camera publishers and viewer of one simulated HAL on one node."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        description: RobotDescription,
        pacer: Pacer,
        *,
        lock: threading.Lock | None = None,
        viewer_enabled: bool = True,
        camera_rates_hz: Mapping[str, float] | None = None,
        viewer_sync_rate_hz: float = 30.0,
        served_elsewhere: frozenset[str] = frozenset(),
    ) -> None:
        """Nothing is created until :meth:`setup`.

        Args:
            node: The rclpy node that owns the publishers.
            hal: A connected HAL; images need :class:`CameraHal`, the viewer
                :class:`MujocoBacked`.
            description: The robot's manifest (sensors, rates, frame ids).
            pacer: Runs the cameras' and the viewer's periodic jobs.
            lock: The HAL's lock, held while a job reads the HAL or the live scene
                (default: a lock of the bridge's own).
            viewer_enabled: Open the MuJoCo passive viewer when a display exists.
            camera_rates_hz: Publish rate of each camera [Hz] by sensor name (as
                :func:`~openral_sim.sensor_schedule.sensor_rates` gives them); None, or a
                camera missing here: the sensor's ``rate_hz``.
            viewer_sync_rate_hz: How often the viewer is synchronised [Hz].
            served_elsewhere: Depth and lidar sensors another bridge publishes (the rest
                are reported as not published).

        Raises:
            ValueError: A rate that is not positive.
        """
        rates = {f"camera_rates_hz[{k!r}]": v for k, v in (camera_rates_hz or {}).items()}
        for label, rate in {**rates, "viewer_sync_rate_hz": viewer_sync_rate_hz}.items():
            if not rate > 0:
                raise ValueError(f"{label} must be > 0 Hz, got {rate}")
        self.node = node
        self.hal = hal
        self.description = description
        self.pacer = pacer
        self.lock = lock if lock is not None else threading.Lock()
        self.viewer_enabled = viewer_enabled
        self.camera_rates_hz = dict(camera_rates_hz or {})
        self.viewer_sync_rate_hz = viewer_sync_rate_hz
        self.served_elsewhere = served_elsewhere
        self._cameras: dict[str, _Camera] = {}
        self._count_lock = threading.Lock()
        self._camera_hal: CameraHal | None = None
        self._observing: ObservationFrames | None = None
        self._observed_before = True
        self._frames: FrameRenderer[ImageArray] | None = None
        self._viewer: Any = None
        self._viewer_job: PacedJob | None = None
        self.on_frame: Callable[[str, ImageArray, float], None] | None = None
        """Called with (camera, frame, stamp [s]) after each frame is published."""
        self.gate: SnapshotGate | None = None
        """When a paced snapshot may be taken (None: whenever it is due)."""

    # -- lifecycle -------------------------------------------------------------------------

    @property
    def active(self) -> bool:
        """True between :meth:`setup` and :meth:`teardown`."""
        return bool(self._cameras or self._viewer)

    @property
    def camera_rates(self) -> dict[str, float]:
        """Publish rate of each published camera, by sensor name [Hz]."""
        return {name: camera.rate_hz for name, camera in self._cameras.items()}

    @property
    def frames_published(self) -> int:
        """Image messages published since :meth:`setup`, all cameras together."""
        return sum(self.published_counts().values())

    def published_counts(self) -> dict[str, int]:
        """Image messages published since :meth:`setup`, by sensor name."""
        with self._count_lock:
            return {name: camera.published for name, camera in self._cameras.items()}

    @property
    def frames_skipped(self) -> int:
        """Due frames not rendered because that camera's previous frame was in flight."""
        return sum(self._frames.skipped.values()) if self._frames else 0

    def setup(self) -> None:
        """Create the publishers and pacer jobs the manifest and HAL allow, and publish
        once."""
        self.teardown()
        self._setup_cameras()
        self._setup_viewer()
        self._report_unrendered()

    def teardown(self) -> None:
        """Cancel every job, stop the render thread, destroy every publisher and close the
        viewer (idempotent; call it without holding the HAL's lock)."""
        self._stop_camera_jobs()
        if self._frames is not None:
            frames, self._frames = self._frames, None
            if not frames.stop():
                self._log().warning("the camera render thread did not stop within its timeout")
        if self._observing is not None:
            self._observing.render_in_observations(self._observed_before)
            self._observing = None
        for camera in self._cameras.values():
            for publisher in (camera.image_pub, camera.info_pub):
                if publisher is not None:
                    self.node.destroy_publisher(publisher)
        self._cameras.clear()
        self._camera_hal = None
        if self._viewer_job is not None:
            self.pacer.cancel(self._viewer_job)
            self._viewer_job = None
        if self._viewer is not None:
            viewer, self._viewer = self._viewer, None
            viewer.close()

    def topics(self) -> list[TopicInfo]:
        """What the bridge publishes now, each camera at its own rate."""
        rows = []
        for name, camera in self._cameras.items():
            rows.append(TopicInfo(camera_image(name), "sensor_msgs/msg/Image", camera.rate_hz))
            if camera.info_pub is not None:
                info = camera_info(name)
                rows.append(TopicInfo(info, "sensor_msgs/msg/CameraInfo", camera.rate_hz))
        return rows

    # -- cameras ---------------------------------------------------------------------------

    def _setup_cameras(self) -> None:
        hal = self.hal
        if not isinstance(hal, CameraHal):
            return
        source = hal if isinstance(hal, CameraSource) and hal.camera_sensors() else None
        rendered = set(source.camera_sensors()) if source else set(hal.read_images())
        for sensor in self.description.sensors:
            if isinstance(sensor, RgbSensor) and sensor.name in rendered:
                self._add_camera(hal, sensor)
        if not self._cameras:
            return
        self._camera_hal = hal
        if source is not None:
            self._start_renderer(source)
        for name, camera in self._cameras.items():
            period = 1.0 / camera.rate_hz
            camera.job = self.pacer.every(period, partial(self._due, name), f"camera {name}")
        self.publish_now()

    def publish_now(self) -> None:
        """A frame of every camera of the scene as it is now (after a reset, say), whether
        due or not, waiting up to :data:`NOW_WAIT_S` for a frame still in flight; takes the
        HAL's lock."""
        for name in self._cameras:
            self._due(name, wait_s=NOW_WAIT_S)

    def _add_camera(self, hal: CameraHal, sensor: RgbSensor) -> None:
        from sensor_msgs.msg import CameraInfo, Image

        fovy = self._fovy_deg(hal, sensor)
        image = self.node.create_publisher(Image, camera_image(sensor.name), IMAGE_QUEUE_DEPTH)
        info = None
        if fovy is not None:
            topic = camera_info(sensor.name)
            info = self.node.create_publisher(CameraInfo, topic, IMAGE_QUEUE_DEPTH)
        rate = self.camera_rates_hz.get(sensor.name, sensor.rate_hz)
        messages = CameraMessages(sensor.frame_id, fovy)
        self._cameras[sensor.name] = _Camera(sensor, float(rate), messages, image, info)

    def _start_renderer(self, source: CameraSource) -> None:
        """Render the cameras on a thread of their own, each frame drawn straight into its
        camera's reused ``Image``; a scene's observations carry no frames until
        :meth:`teardown`."""
        height, width = source.camera_size()
        out = {
            name: camera.messages.pixels(height, width) for name, camera in self._cameras.items()
        }
        self._frames = FrameRenderer(source.camera_capture(out), self._publish)
        self._frames.start()
        if isinstance(source, ObservationFrames):
            self._observing = source
            self._observed_before = source.render_in_observations(False)

    def _due(self, name: str, wait_s: float = 0.0) -> float | None:
        """A camera's job: request a rendered frame, or publish the last observed one.

        Returns:
            :data:`~openral_bridge.frame_renderer.RETRY_S` when the camera's previous frame
            is still being rendered (the pacer asks again shortly), else None.
        """
        frames = self._frames
        if frames is not None:
            if frames.error is not None:
                self._camera_failed(frames.error)
                return None
            gate = self.gate if wait_s == 0.0 else None
            return frames.request_or_retry(name, self.lock, wait_s=wait_s, gate=gate)
        camera_hal = self._camera_hal
        if camera_hal is None:
            return None
        with self.lock:
            image = camera_hal.read_images().get(name)
            sim_time_s = self._sim_time_s() if image is not None else 0.0
        if image is not None:
            self._publish(name, image, sim_time_s)
        return None

    def _publish(self, name: str, image: npt.NDArray[np.uint8], sim_time_s: float) -> None:
        """Publish one frame and its camera info (pacer or render thread)."""
        camera = self._cameras.get(name)
        if camera is None:
            return
        camera.messages.fill(image)
        image_msg, info_msg = camera.messages.stamped(ros_messages.stamp(sim_time_s))
        camera.image_pub.publish(image_msg)
        if camera.info_pub is not None and info_msg is not None:
            camera.info_pub.publish(info_msg)
        with self._count_lock:
            camera.published += 1
        if self.on_frame is not None:
            self.on_frame(name, image, sim_time_s)

    def _camera_failed(self, error: BaseException) -> None:
        """Report a render thread that stopped, once, and publish no more frames (the
        publishers stay until :meth:`teardown`)."""
        self._log().error(
            f"camera rendering stopped ({type(error).__name__}: {error}); "
            "the robot keeps running without camera images"
        )
        self._stop_camera_jobs()
        self._camera_hal = None
        if self._frames is not None:
            frames, self._frames = self._frames, None
            frames.stop()

    def _stop_camera_jobs(self) -> None:
        for camera in self._cameras.values():
            if camera.job is not None:
                self.pacer.cancel(camera.job)
                camera.job = None

    def _sim_time_s(self) -> float:
        sim_time = self.hal.read_state().sim_time_s
        if sim_time is None:
            return float(self.node.get_clock().now().nanoseconds) / 1e9
        return float(sim_time)

    def _fovy_deg(self, hal: CameraHal, sensor: RgbSensor) -> float | None:
        """Vertical field of view [deg]: the scene camera's, else the manifest's."""
        fovy = hal.camera_fovy_deg(sensor.name)
        if fovy is not None:
            return float(fovy)
        if sensor.fovy_deg is not None:
            return float(sensor.fovy_deg)
        self._log().warning(
            f"camera {sensor.name!r}: no scene camera found and no fovy_deg in the manifest; "
            "its camera_info is not published"
        )
        return None

    def _handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        return self.hal.mujoco_handles() if isinstance(self.hal, MujocoBacked) else None

    # -- viewer ----------------------------------------------------------------------------

    def _setup_viewer(self) -> None:
        if not self.viewer_enabled:
            return
        log = self._log()
        handles = self._handles()
        if handles is None:
            log.warning("viewer requested but the HAL has no MuJoCo model; running without it")
            return
        if not has_display():
            log.warning("no display (DISPLAY and WAYLAND_DISPLAY unset); running headless")
            return
        try:
            import mujoco.viewer

            self._viewer = mujoco.viewer.launch_passive(*handles)
        except Exception as error:  # a broken GL stack must not stop the robot
            log.warning(f"viewer unavailable ({type(error).__name__}: {error}); running headless")
            return
        period = 1.0 / self.viewer_sync_rate_hz
        self._viewer_job = self.pacer.every(period, self._sync_viewer, "viewer")

    def _sync_viewer(self) -> None:
        viewer = self._viewer
        if viewer is None:
            return
        if viewer.is_running():
            with self.lock:
                viewer.sync()
            return
        self._log().info("viewer closed; the node keeps running")
        if self._viewer_job is not None:
            self.pacer.cancel(self._viewer_job)
        self._viewer_job = self._viewer = None
        viewer.close()

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]

    # -- reporting -------------------------------------------------------------------------

    def _report_unrendered(self) -> None:
        skipped = [
            f"{s.name} ({s.kind})"
            for s in self.description.sensors
            if (isinstance(s, DepthSensor | SiteSensor) and s.name not in self.served_elsewhere)
            or (isinstance(s, RgbSensor) and s.name not in self._cameras)
        ]
        if skipped:
            why = (
                "no device names them: a sensor's `device`, or --camera NAME=DEVICE"
                if self.hal.is_real
                else "the scene does not render them"
            )
            self._log().info(f"not published ({why}): {', '.join(skipped)}")
