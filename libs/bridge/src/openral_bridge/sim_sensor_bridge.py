"""SimSensorBridge: publish what a simulated scene's sensors see, and keep the scene alive.

One bridge serves every robot; what it publishes follows the manifest and what the HAL
can do:

- each manifest RGB sensor the scene renders → ``sensor_msgs/Image`` (rgb8) on
  ``/openral/cameras/<name>/image`` and ``sensor_msgs/CameraInfo`` on
  ``/openral/cameras/<name>/camera_info`` at ``camera_rate_hz``, frame id from the manifest;
- an idle-step timer at the same rate, only for a HAL that can idle-step (never a real
  one), advancing the scene while no action has arrived for ``idle_hold_ms``;
- the MuJoCo passive viewer when enabled and a display exists.

Header stamps are simulation time (MuJoCo ``data.time``; the node publishes ``/clock``),
so a frame's stamp says which physics state it shows; a HAL without simulation time
stamps with the node clock. Depth and lidar sensors are not rendered by the scenes yet
and are reported, not published.

The bridge runs on the node's single-threaded executor: its timers never run at the same
time as the node's ``/openral/safe_action`` callback, which is the whole hand-off rule.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import mujoco
from openral_core.models import DepthSensor, LidarSensor, RgbSensor, RobotDescription
from openral_hal.factory import can_idle_step
from openral_hal.protocol import CameraHal, IdleSteppable, MujocoBacked, RobotHal
from openral_mujoco.display import has_display

from openral_bridge import ros_messages
from openral_bridge.idle import should_idle_step
from openral_bridge.topics import camera_image, camera_info

if TYPE_CHECKING:
    from rclpy.node import Node

IMAGE_QUEUE_DEPTH = 5
"""Reliable queue of the image publishers: a slow subscriber drops old frames, not new."""


@dataclass(frozen=True)
class TopicInfo:
    """One topic a node publishes: name, message type and nominal rate (None: on change)."""

    name: str
    type: str
    rate_hz: float | None


class SimSensorBridge:
    """Camera publishers, idle stepper and viewer of one simulated HAL on one node."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        description: RobotDescription,
        *,
        viewer_enabled: bool = True,
        camera_rate_hz: float = 10.0,
        viewer_sync_rate_hz: float = 30.0,
        idle_hold_ms: float = 200.0,
    ) -> None:
        """Nothing is created until :meth:`setup`.

        Args:
            node: The rclpy node that owns the publishers and timers.
            hal: A connected HAL; images need :class:`CameraHal`, idle stepping a simulated
                :class:`IdleSteppable`, the viewer :class:`MujocoBacked`.
            description: The robot's manifest (sensors, frame ids).
            viewer_enabled: Open the MuJoCo passive viewer when a display exists.
            camera_rate_hz: Camera publish rate, also the idle-step rate [Hz].
            viewer_sync_rate_hz: How often the viewer is synchronised [Hz].
            idle_hold_ms: Quiet time after an action before idle stepping resumes [ms].

        Raises:
            ValueError: A rate that is not positive or a negative hold.
        """
        rates = {"camera_rate_hz": camera_rate_hz, "viewer_sync_rate_hz": viewer_sync_rate_hz}
        for label, rate in rates.items():
            if not rate > 0:
                raise ValueError(f"{label} must be > 0 Hz, got {rate}")
        if idle_hold_ms < 0:
            raise ValueError(f"idle_hold_ms must be >= 0 ms, got {idle_hold_ms}")
        self.node = node
        self.hal = hal
        self.description = description
        self.viewer_enabled = viewer_enabled
        self.camera_rate_hz = camera_rate_hz
        self.viewer_sync_rate_hz = viewer_sync_rate_hz
        self.idle_hold_ns = int(idle_hold_ms * 1e6)
        self.idle_steps = 0
        """Scene steps taken by the idle stepper since :meth:`setup`."""
        self.frames_published = 0
        """Camera ticks that published at least one image since :meth:`setup`."""
        self._cameras: dict[str, tuple[RgbSensor, float | None]] = {}
        self._publishers: list[Any] = []
        self._image_pubs: dict[str, tuple[Any, Any | None]] = {}
        self._camera_timer: Any = None
        self._camera_hal: CameraHal | None = None
        self._stepper: IdleSteppable | None = None
        self._idle_timer: Any = None
        self._viewer: Any = None
        self._viewer_timer: Any = None

    # -- lifecycle -------------------------------------------------------------------------

    @property
    def active(self) -> bool:
        """True between :meth:`setup` and :meth:`teardown`."""
        return bool(self._publishers or self._idle_timer or self._viewer)

    @property
    def idle_stepping(self) -> bool:
        """True while the idle-step timer exists (set up and not disabled by a fault)."""
        return self._idle_timer is not None

    def setup(self) -> None:
        """Create the publishers and timers the manifest and HAL allow, and publish once."""
        self.teardown()
        self.idle_steps = self.frames_published = 0
        self._setup_idle_stepper()  # first: on a shared tick the step runs before the publish
        self._setup_cameras()
        self._setup_viewer()
        self._report_unrendered()

    def teardown(self) -> None:
        """Destroy every timer and publisher and close the viewer (idempotent)."""
        for timer in (self._camera_timer, self._idle_timer, self._viewer_timer):
            if timer is not None:
                self.node.destroy_timer(timer)
        self._camera_timer = self._idle_timer = self._viewer_timer = None
        for publisher in self._publishers:
            self.node.destroy_publisher(publisher)
        self._publishers.clear()
        self._image_pubs.clear()
        self._cameras.clear()
        self._camera_hal = self._stepper = None
        if self._viewer is not None:
            viewer, self._viewer = self._viewer, None
            viewer.close()

    def topics(self) -> list[TopicInfo]:
        """What the bridge publishes now."""
        rate = self.camera_rate_hz
        rows = []
        for name, (_, info_pub) in self._image_pubs.items():
            rows.append(TopicInfo(camera_image(name), "sensor_msgs/msg/Image", rate))
            if info_pub is not None:
                info = camera_info(name)
                rows.append(TopicInfo(info, "sensor_msgs/msg/CameraInfo", rate))
        return rows

    # -- cameras ---------------------------------------------------------------------------

    def _setup_cameras(self) -> None:
        hal = self.hal
        if not isinstance(hal, CameraHal):
            return
        from sensor_msgs.msg import CameraInfo, Image

        rendered = hal.read_images()
        for sensor in self.description.sensors:
            if not isinstance(sensor, RgbSensor) or sensor.name not in rendered:
                continue
            fovy = self._fovy_deg(hal, sensor)
            self._cameras[sensor.name] = (sensor, fovy)
            image = self.node.create_publisher(Image, camera_image(sensor.name), IMAGE_QUEUE_DEPTH)
            self._publishers.append(image)
            info = None
            if fovy is not None:
                topic = camera_info(sensor.name)
                info = self.node.create_publisher(CameraInfo, topic, IMAGE_QUEUE_DEPTH)
                self._publishers.append(info)
            self._image_pubs[sensor.name] = (image, info)
        if self._image_pubs:
            self._camera_hal = hal
            self._publish_images()
            self._camera_timer = self.node.create_timer(
                1.0 / self.camera_rate_hz, self._publish_images
            )

    def _publish_images(self) -> None:
        if self._camera_hal is None:
            return
        images = self._camera_hal.read_images()
        stamp = ros_messages.stamp(self._sim_time_s())
        published = False
        for name, (image_pub, info_pub) in self._image_pubs.items():
            image = images.get(name)
            if image is None:
                continue
            sensor, fovy = self._cameras[name]
            image_pub.publish(ros_messages.image_msg(image, stamp, sensor.frame_id))
            if info_pub is not None and fovy is not None:
                height, width = image.shape[:2]
                info = ros_messages.camera_info_msg(width, height, fovy, stamp, sensor.frame_id)
                info_pub.publish(info)
            published = True
        self.frames_published += int(published)

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

    # -- idle stepper ----------------------------------------------------------------------

    def _setup_idle_stepper(self) -> None:
        if can_idle_step(self.hal):
            self._stepper = self.hal
            self._idle_timer = self.node.create_timer(1.0 / self.camera_rate_hz, self._idle_tick)

    def _idle_tick(self) -> None:
        stepper = self._stepper
        if stepper is None:
            return
        if not should_idle_step(time.monotonic_ns(), stepper.last_action_ns, self.idle_hold_ns):
            return
        try:
            stepped = stepper.idle_step()
        except Exception as error:  # one report, then the stepper is off for good
            self._log().error(f"idle stepping disabled after {type(error).__name__}: {error}")
            if self._idle_timer is not None:
                self.node.destroy_timer(self._idle_timer)
                self._idle_timer = None
            return
        self.idle_steps += int(bool(stepped))

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
        self._viewer_timer = self.node.create_timer(
            1.0 / self.viewer_sync_rate_hz, self._sync_viewer
        )

    def _sync_viewer(self) -> None:
        viewer = self._viewer
        if viewer is None:
            return
        if viewer.is_running():
            viewer.sync()
            return
        self._log().info("viewer closed; the node keeps running")
        self.node.destroy_timer(self._viewer_timer)
        self._viewer_timer = self._viewer = None
        viewer.close()

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]

    # -- reporting -------------------------------------------------------------------------

    def _report_unrendered(self) -> None:
        skipped = [
            f"{s.name} ({s.kind})"
            for s in self.description.sensors
            if isinstance(s, DepthSensor | LidarSensor)
            or (isinstance(s, RgbSensor) and s.name not in self._image_pubs)
        ]
        if skipped:
            self._log().info(
                f"not published (the scene does not render them): {', '.join(skipped)}"
            )
