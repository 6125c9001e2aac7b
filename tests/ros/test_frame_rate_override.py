"""``deploy sim --camera-rate`` (the node's ``camera_publish_rate_hz``) sets the rate of every
RGB camera, depth camera and lidar alike; IMU-like sensors keep theirs; nothing exceeds the
control rate. Checked on the mobile room (a wrist camera, a head depth camera, a lidar) with
the bridges ``deploy sim`` builds (``SceneBridges``), and on the rule itself."""

from __future__ import annotations

import math
import threading

import pytest
from openral_bridge.pacer import Pacer
from openral_core import load_scene, open_robot_by_id
from openral_core.registry import load_robot_by_id
from openral_hal.factory import HalMode, build_hal
from openral_nodes.runtime import Spinner
from openral_nodes.scene_bridges import SceneBridges
from openral_sim.sensor_schedule import SensorSchedule, sensor_rates
from rclpy.context import Context
from rclpy.node import Node

from tests.conftest import ROBOTS

ROOM = ROBOTS / "panda_mobile" / "scenes" / "room.yaml"
IMAGING = (
    "/openral/cameras/wrist/image",
    "/openral/cameras/head_depth/depth",
    "/openral/cameras/head_depth/points",
    "/scan",
)


def _rates(context: Context, camera_rate_hz: float | None) -> dict[str, float | None]:
    hal = build_hal(open_robot_by_id("panda_mobile"), mode=HalMode.SIM, scene=load_scene(ROOM))
    hal.connect()
    node = Node("frame_rate_override_test", context=context)
    bridges = SceneBridges(
        node,
        hal,
        Pacer(),  # never started: only the schedule is looked at
        threading.Lock(),
        viewer_enabled=False,
        camera_rate_hz=camera_rate_hz,
        odom_rate_hz=20.0,
    )
    try:
        with Spinner(context) as spinner:
            spinner.add_node(node)
            spinner.call(bridges.setup)
            rates = {row.name: row.rate_hz for row in bridges.topics()}
            spinner.call(bridges.teardown)
    finally:
        node.destroy_node()  # type: ignore[no-untyped-call]
        hal.disconnect()
    return rates


def test_the_override_changes_rgb_depth_and_lidar_alike(ros_context: Context) -> None:
    own = _rates(ros_context, None)
    assert [own[topic] for topic in IMAGING] == [10.0, 5.0, 5.0, 10.0]  # the manifest's
    slow = _rates(ros_context, 4.0)
    assert [slow[topic] for topic in IMAGING] == [4.0, 4.0, 4.0, 4.0]
    fast = _rates(ros_context, 50.0)
    assert [fast[topic] for topic in IMAGING] == [20.0, 20.0, 20.0, 20.0]  # the control rate


def test_the_rule_leaves_state_sensors_alone_and_caps_at_the_control_rate() -> None:
    g1 = load_robot_by_id("g1")
    rates = sensor_rates(g1, 50.0, frame_rate_hz=2.0)
    assert rates == {"head": 2.0, "head_depth": 2.0, "lidar": 2.0, "pelvis_imu": 50.0}
    assert sensor_rates(g1, None)["pelvis_imu"] == 200.0  # a real robot: no cap
    assert sensor_rates(g1, 20.0, frame_rate_hz=math.inf)["head"] == 20.0  # every step
    with pytest.raises(ValueError, match="frame rate must be a positive number of Hz"):
        sensor_rates(g1, 20.0, frame_rate_hz=0.0)


def test_a_schedule_makes_a_sensor_due_once_per_period_without_bursts() -> None:
    schedule = SensorSchedule({"camera": 10.0, "imu": 20.0})
    due = [sorted(schedule.due(step * 0.05)) for step in range(5)]
    assert due == [["camera", "imu"], ["imu"], ["camera", "imu"], ["imu"], ["camera", "imu"]]
    assert schedule.due(10.0) == {"camera", "imu"}  # after a pause: due once, not 76 times
    assert schedule.due(10.05) == {"imu"}
    schedule.restart()
    assert schedule.due(10.06) == {"camera", "imu"}
