"""SceneBridges: everything a simulated robot publishes and takes beyond its joints.

- cameras and the viewer (:class:`~openral_bridge.sim_sensor_bridge.SimSensorBridge`);
- depth cameras (image, camera info, cloud) and lidars (scans) of a HAL that serves them
  (:class:`~openral_bridge.range_bridge.RangeBridge`), and its IMU, force-torque and pose
  sensors (:class:`~openral_bridge.state_sensor_bridge.StateSensorBridge`): whatever HAL
  implements the sensor Protocols (:mod:`openral_sim.sensor_sources`), simulated or real;
- for a robot with a mobile base, ``/cmd_vel`` in and ``/odom`` out
  (:class:`~openral_bridge.base_bridge.BaseBridge`, at the joint-state rate);
- for a robot with a tool centre point in a native scene, ``/openral/ee_target`` in and
  ``/openral/tcp_pose`` out (:class:`~openral_bridge.ee_bridge.EeBridge`, at the
  joint-state rate);
- with a ``view_port``, the browser view (:class:`~openral_bridge.view_bridge.ViewBridge`):
  the scene's bodies, joints and camera frames in Rerun's web viewer.

Every sensor's rate comes from one rule (:func:`~openral_sim.sensor_schedule.sensor_rates`):
its manifest rate, the ``camera_rate_hz`` override applied to RGB, depth and lidar alike,
capped at the control rate of a ticked HAL; cameras, depth and lidars take the scene at
a control period's end (:mod:`openral_bridge.snapshot_gate`). All their periodic work
runs on the node's pacer and every call into the HAL or the live scene holds the node's
HAL lock. A sensor none of them serves is reported once at setup.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

from openral_bridge.base_bridge import BaseBridge
from openral_bridge.control_loop import ControlLoop
from openral_bridge.ee_bridge import EeBridge
from openral_bridge.pacer import Pacer
from openral_bridge.range_bridge import RangeBridge
from openral_bridge.sim_sensor_bridge import SimSensorBridge
from openral_bridge.snapshot_gate import period_end_gate
from openral_bridge.state_sensor_bridge import StateSensorBridge
from openral_bridge.topics import TopicInfo
from openral_bridge.view_bridge import ViewBridge
from openral_core.loaded import LoadedRobot
from openral_hal.factory import can_tick
from openral_hal.protocol import MobileBaseHal, MujocoBacked, RobotHal
from openral_hal.sim_attached import SimAttachedHAL
from openral_hal.tool_centre import ee_command
from openral_hal.view_feed import ViewFeed
from openral_sim.sensor_schedule import sensor_rates
from openral_sim.sensor_sources import (
    CameraSource,
    DepthSource,
    LidarSource,
    StateSensorSource,
)

if TYPE_CHECKING:
    from rclpy.node import Node


class SceneBridges:
    """The camera, range-sensor and mobile-base bridges of one HAL on one node."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        pacer: Pacer,
        lock: threading.Lock,
        *,
        viewer_enabled: bool,
        camera_rate_hz: float | None,
        odom_rate_hz: float,
        loop: ControlLoop | None = None,
        robot: LoadedRobot | None = None,
        view_port: int = 0,
    ) -> None:
        """Nothing is created until :meth:`setup` (see the bridges for the arguments)."""
        control_hz = 1.0 / hal.control_period_s if can_tick(hal) else None
        rates = sensor_rates(hal.description, control_hz, frame_rate_hz=camera_rate_hz)
        depth = hal if isinstance(hal, DepthSource) else None
        lidar = hal if isinstance(hal, LidarSource) else None
        self.range = RangeBridge(node, depth, lidar, lock, rates)
        served = frozenset(self.range.depth) | frozenset(self.range.lidars)
        self.state = None
        if isinstance(hal, StateSensorSource):
            self.state = StateSensorBridge(node, hal, lock, rates)
            served |= self.state.served
        self.base = None
        if isinstance(hal, MobileBaseHal) and hal.base is not None:
            self.base = BaseBridge(node, hal, odom_rate_hz, lock, loop)
        self.ee = _ee_bridge(node, hal, loop, robot, odom_rate_hz, lock)
        self.sensors = SimSensorBridge(
            node,
            hal,
            hal.description,
            pacer,
            lock=lock,
            viewer_enabled=viewer_enabled,
            camera_rates_hz=rates,
            served_elsewhere=served,
        )
        if loop is not None:  # imaging sensors show period-end states, as `sim run` does
            self.range.gate = self.sensors.gate = period_end_gate(loop)
        self.pacer = pacer
        self.view_port = view_port
        self.view: ViewBridge | None = None
        self._view_args = (node, hal, lock)

    def setup(self) -> None:
        """Start every bridge; each publishes once now."""
        self.view = _view_bridge(*self._view_args, self.view_port) if self.view_port else None
        if self.view is not None:
            self.sensors.on_frame = self.view.frame
            self.view.start(self.pacer)
        self.sensors.setup()
        if self.range is not None:
            self.range.start(self.pacer)
        if self.state is not None:
            self.state.start(self.pacer)
        if self.base is not None:
            self.base.start(self.pacer)
        if self.ee is not None:
            self.ee.start(self.pacer)

    def publish_now(self) -> None:
        """Every camera, depth camera and lidar publishes the scene as it is now (after a
        reset); takes the HAL's lock."""
        self.sensors.publish_now()
        if self.range is not None:
            self.range.publish_now()
        if self.state is not None:
            self.state.publish_now()

    def teardown(self) -> None:
        """Stop every bridge (idempotent)."""
        if self.view is not None:
            self.view.stop()
        if self.ee is not None:
            self.ee.stop()
        if self.base is not None:
            self.base.stop()
        if self.state is not None:
            self.state.stop()
        if self.range is not None:
            self.range.stop()
        self.sensors.teardown()

    def topics(self) -> list[TopicInfo]:
        """What the bridges publish now, with their nominal rates."""
        rows = self.sensors.topics()
        rows += self.range.topics() if self.range is not None else []
        rows += self.state.topics() if self.state is not None else []
        rows += self.ee.topics() if self.ee is not None else []
        return rows + (self.base.topics() if self.base is not None else [])


def _ee_bridge(
    node: Node,
    hal: RobotHal,
    loop: ControlLoop | None,
    robot: LoadedRobot | None,
    rate_hz: float,
    lock: threading.Lock,
) -> EeBridge | None:
    """The end-effector bridge of a simulated HAL whose action slots are the manifest
    joints, in a native scene, of a robot with a TCP (else None)."""
    if loop is None or robot is None or not isinstance(hal, SimAttachedHAL):
        return None
    if hal.action_names != hal.joint_names:
        return None
    with lock:
        ee = ee_command(hal, robot)
    return EeBridge(node, hal, ee, loop, rate_hz, lock) if ee is not None else None


def _view_bridge(node: Node, hal: RobotHal, lock: threading.Lock, port: int) -> ViewBridge | None:
    """The browser view on ``port`` (its data on the next one), or None with the reason
    logged: no MuJoCo model, rerun-sdk missing, a port taken. The robot runs either way."""
    log = node.get_logger()  # type: ignore[no-untyped-call]
    handles = hal.mujoco_handles() if isinstance(hal, MujocoBacked) else None
    if handles is None:
        log.error("view: the HAL has no MuJoCo model to draw; running without the view")
        return None
    try:
        from openral_sim.browser_view import BrowserView, ViewPorts, ViewUnavailable
    except ImportError:
        log.error("view: rerun-sdk is missing (pip install 'openral[view]'); running without it")
        return None
    cameras = tuple(hal.camera_sensors()) if isinstance(hal, CameraSource) else ()
    title = f"deploy sim · {hal.description.name}"
    try:
        with lock:
            view = BrowserView(handles[0], title=title, cameras=cameras, ports=ViewPorts(port))
    except ViewUnavailable as error:
        log.error(f"view: {error}; running without the view")
        return None
    return ViewBridge(hal, ViewFeed(view, hal), lock)
