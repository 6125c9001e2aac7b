"""Tests for range_bridge.py on the franka tabletop's depth camera: it publishes depth,
camera info and a cloud at the sensor's rate from its own thread, and a depth renderer
that fails is reported once and its job ends, as a camera's does."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest
from openral_bridge.pacer import Pacer
from openral_bridge.range_bridge import RangeBridge
from openral_core import open_robot_by_id
from openral_core.loader import load_scene
from openral_nodes.runtime import Spinner
from openral_sim.native_scene import NativeScene
from rclpy.context import Context
from rclpy.node import Node

from tests.ros.ros_helpers import FRANKA_SCENE, wait_until


@pytest.fixture
def bridge(ros_context: Context) -> Iterator[tuple[RangeBridge, Pacer]]:
    scene = NativeScene(load_scene(FRANKA_SCENE), open_robot_by_id("franka_panda"))
    scene.reset(0)
    node = Node("range_bridge_test", context=ros_context)
    sensors = scene.sensors
    bridge, pacer = RangeBridge(node, sensors, sensors, threading.Lock(), {}), Pacer()
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.start, pacer)
        pacer.start()
        yield bridge, pacer
        assert pacer.stop()
        spinner.call(bridge.stop)
    node.destroy_node()  # type: ignore[no-untyped-call]
    scene.close()


def test_the_depth_camera_publishes_its_three_topics(bridge: tuple[RangeBridge, Pacer]) -> None:
    range_bridge, pacer = bridge
    assert {t.name for t in range_bridge.topics()} == {
        "/openral/cameras/front_depth/depth",
        "/openral/cameras/front_depth/camera_info",
        "/openral/cameras/front_depth/points",
    }
    assert [round(1.0 / job.period_s, 6) for job in pacer.jobs] == [5.0]
    wait_until(lambda: range_bridge.published_counts()["front_depth"] >= 2, what="depth frames")


def test_a_failed_depth_renderer_is_reported_once_and_its_job_ends(
    bridge: tuple[RangeBridge, Pacer],
) -> None:
    range_bridge, pacer = bridge
    frames = range_bridge._streams["front_depth"].frames
    assert frames is not None
    frames.error = RuntimeError("no GL context")
    wait_until(lambda: not pacer.jobs, what="the depth job to end")
    # a frame requested before the error may still be in flight: it ends, then nothing more
    wait_until(lambda: not frames._slots["front_depth"].busy, what="the last frame to end")
    published = range_bridge.published_counts()["front_depth"]
    range_bridge._due("front_depth")  # a late call changes nothing and raises nothing
    assert range_bridge.published_counts()["front_depth"] == published
