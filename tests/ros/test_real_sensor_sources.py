"""A real robot's sensors go through the same bridges as a simulation's.

``FakeRealG1`` is an honest stand-in for a hardware driver of the Unitree G1: no MuJoCo,
``is_real`` true, never ticked; it serves the manifest's depth camera, lidar and IMU
through the sensor Protocols (:mod:`openral_sim.sensor_sources`), with values a test can
recognise. ``SceneBridges`` — exactly what ``deploy`` builds — publishes them, and an
outside subscriber reads them back.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Mapping

import numpy as np
import pytest
from geometry_msgs.msg import Vector3
from openral_bridge.pacer import Pacer
from openral_core.models import DepthSensor, LidarSensor, RobotDescription, StateSensor
from openral_core.registry import load_robot_by_id
from openral_hal.errors import EStopLatched
from openral_hal.factory import can_tick
from openral_hal.protocol import DepthSource, LidarSource, RobotHal, StateSensorSource
from openral_mujoco.state import FloatArray, JointStateSample
from openral_nodes.runtime import Spinner
from openral_nodes.scene_bridges import SceneBridges
from openral_sim.depth_cloud import DepthFrame
from openral_sim.observation import LidarScan
from openral_sim.sensor_sources import DepthSpec, LidarSpec, StateSpec
from openral_sim.state_sensors import ImuReading, Reading
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import Image, Imu, LaserScan, PointCloud2

from tests.ros.ros_helpers import Probe

DEPTH_M = 1.25
"""Every pixel of the fake depth camera [m]."""
RANGE_M = 3.5
"""Every ray of the fake lidar [m]."""


class _DepthDeveloper:
    def __init__(self, spec: DepthSpec, times: dict[str, float]) -> None:
        self.spec, self.times = spec, times

    def develop(self, sensor: str) -> DepthFrame:
        depth = np.full((self.spec.height, self.spec.width), DEPTH_M, dtype=np.float32)
        points = np.array([[DEPTH_M, 0.0, 0.5]], dtype=np.float32)
        return DepthFrame(depth, points, self.times[sensor])

    def close(self) -> None:
        pass


class _DepthCapture:
    """A driver's frame buffer: a snapshot notes the time, developing makes the frame."""

    def __init__(self, spec: DepthSpec, clock: FakeRealG1) -> None:
        self.spec, self.clock = spec, clock
        self.times: dict[str, float] = {}

    @property
    def sensors(self) -> tuple[str, ...]:
        return (self.spec.sensor.name,)

    def snapshot(self, sensor: str) -> float:
        self.times[sensor] = self.clock.now_s()
        return self.times[sensor]

    def open(self) -> _DepthDeveloper:
        return _DepthDeveloper(self.spec, self.times)


class FakeRealG1:
    """The G1's real-hardware HAL, without hardware: sensors answer with fixed values."""

    is_real = True

    def __init__(self, description: RobotDescription) -> None:
        self.description = description
        self.joint_names = tuple(j.name for j in description.joints)
        self.action_names = self.joint_names
        self.connected = False
        self.estopped = False
        self.started = time.monotonic()
        sensors = {s.name: s for s in description.sensors}
        depth, lidar, imu = sensors["head_depth"], sensors["lidar"], sensors["pelvis_imu"]
        assert isinstance(depth, DepthSensor) and isinstance(lidar, LidarSensor)
        assert isinstance(imu, StateSensor)
        self._depth = DepthSpec(depth, depth.width, depth.height, 58.0, "pelvis")
        first, last = (math.radians(a) for a in lidar.angle_range_deg)
        self._lidar = LidarSpec(lidar, first, last, *lidar.range_m)
        self._imu = StateSpec(imu, imu.frame_id)

    def now_s(self) -> float:
        return time.monotonic() - self.started

    # -- RobotHal --------------------------------------------------------------------------
    def connect(self) -> None:
        self.connected = True

    def disconnect(self) -> None:
        self.connected = False

    def read_state(self) -> JointStateSample:
        zeros = np.zeros(len(self.joint_names))
        return JointStateSample(self.joint_names, zeros, zeros, zeros, time.monotonic_ns())

    def hold_action(self) -> FloatArray:
        return np.zeros(len(self.joint_names))

    def send_action(self, action: object) -> None:
        if self.estopped:
            raise EStopLatched()

    def estop(self) -> None:
        self.estopped = True

    def release_estop(self) -> None:
        self.estopped = False

    # -- sensor sources --------------------------------------------------------------------
    def depth_sensors(self) -> Mapping[str, DepthSpec]:
        return {"head_depth": self._depth}

    def depth_capture(self, name: str) -> _DepthCapture:
        if name != "head_depth":
            raise KeyError(name)
        return _DepthCapture(self._depth, self)

    def lidar_sensors(self) -> Mapping[str, LidarSpec]:
        return {"lidar": self._lidar}

    def scan(self, name: str) -> LidarScan:
        width = self._lidar.sensor.width
        return LidarScan(np.full(width, RANGE_M, dtype=np.float32), self.now_s())

    def state_sensors(self) -> Mapping[str, StateSpec]:
        return {"pelvis_imu": self._imu}

    def read_sensor(self, name: str) -> Reading:
        if name != "pelvis_imu":
            raise KeyError(name)
        upright = np.array([0.0, 0.0, 0.0, 1.0])
        gravity = np.array([0.0, 0.0, 9.81])
        return ImuReading(upright, np.array([0.0, 0.0, 0.5]), gravity, self.now_s())


def _vector(v: Vector3) -> list[float]:
    return [v.x, v.y, v.z]


@pytest.fixture(scope="module")
def g1() -> FakeRealG1:
    return FakeRealG1(load_robot_by_id("g1"))


def test_the_fake_is_a_real_hal_with_sensor_sources(g1: FakeRealG1) -> None:
    assert isinstance(g1, RobotHal) and not can_tick(g1)
    assert isinstance(g1, DepthSource) and isinstance(g1, LidarSource)
    assert isinstance(g1, StateSensorSource)


def test_depth_lidar_and_imu_of_a_real_hal_reach_ros(ros_context: Context, g1: FakeRealG1) -> None:
    node = Node("real_sensors_test", context=ros_context)
    topics = {
        "/openral/cameras/head_depth/depth": Image,
        "/openral/cameras/head_depth/points": PointCloud2,
        "/scan": LaserScan,
        "/openral/imu/pelvis_imu": Imu,
    }
    probe = Probe(ros_context, topics, name="real_sensors_probe")
    pacer = Pacer()
    g1.connect()
    bridges = SceneBridges(
        node,
        g1,
        pacer,
        threading.Lock(),
        viewer_enabled=False,
        camera_rate_hz=None,
        odom_rate_hz=20.0,
    )
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        spinner.call(bridges.setup)
        pacer.start()
        try:
            received = {topic: probe.wait_count(topic, 2)[-1].msg for topic in topics}
            rates = {row.name: row.rate_hz for row in bridges.topics()}
        finally:
            assert pacer.stop()
            spinner.call(bridges.teardown)
    probe.node.destroy_node()  # type: ignore[no-untyped-call]
    node.destroy_node()  # type: ignore[no-untyped-call]
    depth = received["/openral/cameras/head_depth/depth"]
    assert (depth.height, depth.width, depth.encoding) == (48, 64, "32FC1")
    assert depth.header.frame_id == "head_depth_optical_frame"
    pixels = np.frombuffer(bytes(depth.data), dtype=np.float32)
    assert np.allclose(pixels, DEPTH_M)
    assert received["/openral/cameras/head_depth/points"].header.frame_id == "pelvis"
    scan = received["/scan"]
    assert scan.header.frame_id == "mid360_link" and len(scan.ranges) == 180
    assert np.allclose(scan.ranges, RANGE_M)
    imu = received["/openral/imu/pelvis_imu"]
    assert imu.header.frame_id == "imu_in_pelvis"
    assert _vector(imu.angular_velocity) == [0.0, 0.0, 0.5]
    assert _vector(imu.linear_acceleration) == pytest.approx([0.0, 0.0, 9.81])
    # a real robot is never ticked, so its sensors keep their own rates (no control cap)
    assert rates["/openral/imu/pelvis_imu"] == 200.0 and rates["/scan"] == 10.0
