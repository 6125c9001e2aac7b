"""Tests for sim_sensor_bridge.py on a native scene: frames rendered only when due, on the
render thread, pixel for pixel what the scene draws; a busy or failing renderer never holds
up the control tick. The cameras' jobs and the control tick run on a real Pacer."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator

import mujoco
import numpy as np
import pytest
from openral_bridge.pacer import Pacer
from openral_bridge.sim_sensor_bridge import SimSensorBridge
from openral_core import load_scene, open_robot_by_id
from openral_hal.factory import build_hal
from openral_hal.sim_attached import SimAttachedHAL
from openral_nodes.runtime import Spinner
from openral_sim.native_scene import NativeScene
from openral_sim.sensor_schedule import sensor_rates
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import Image

from tests.ros.ros_helpers import FRANKA_SCENE, Probe, image_topic, wait_until
from tests.ros.test_sim_sensor_bridge import CAMERAS, FRANKA, entity_counts

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone


def every_camera(rate_hz: float) -> dict[str, float]:
    """Every camera of the Panda at ``rate_hz`` (the deploy override's rule)."""
    return sensor_rates(FRANKA, None, frame_rate_hz=rate_hz)


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("native_bridge_test_node", context=ros_context)
    yield node
    node.destroy_node()


@pytest.fixture(scope="module")
def native_hal() -> Iterator[SimAttachedHAL]:
    hal = build_hal(open_robot_by_id("franka_panda"), mode="sim", scene=load_scene(FRANKA_SCENE))
    assert isinstance(hal, SimAttachedHAL) and isinstance(hal.env, NativeScene)
    hal.connect()
    yield hal
    hal.disconnect()


UpdateScene = Callable[..., None]


def patch_update_scene(monkeypatch: pytest.MonkeyPatch, before: Callable[[str], None]) -> None:
    """Call ``before(mjcf camera)`` ahead of every ``mujoco.Renderer.update_scene``."""
    original: UpdateScene = mujoco.Renderer.update_scene

    def patched(self, data, camera=-1, scene_option=None):  # type: ignore[no-untyped-def]
        before(str(camera))
        return original(self, data, camera=camera, scene_option=scene_option)

    monkeypatch.setattr(mujoco.Renderer, "update_scene", patched)


@pytest.fixture
def renders(native_hal: SimAttachedHAL, monkeypatch: pytest.MonkeyPatch) -> Iterator[list[str]]:
    """The sensor of every frame a renderer draws, in order."""
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    sensor_of = {camera: sensor for sensor, camera in scene.camera_models.items()}
    drawn: list[str] = []
    patch_update_scene(monkeypatch, lambda camera: drawn.append(sensor_of[camera]))
    yield drawn


def set_up_at(bridge: SimSensorBridge, scene: NativeScene) -> mujoco.MjData:
    """Set the bridge up; a copy of the scene's data at that instant."""
    bridge.setup()
    snapshot = mujoco.MjData(scene.model)
    mujoco.mj_copyData(snapshot, scene.model, scene.data)
    return snapshot


def test_a_native_scene_renders_a_frame_only_when_one_is_due(
    ros_context: Context,
    node: Node,
    pacer: Pacer,
    native_hal: SimAttachedHAL,
    renders: list[str],
) -> None:
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    probe = Probe(ros_context, {image_topic(c): Image for c in CAMERAS})
    # 0.1 Hz: after the one frame per camera at setup, nothing is due for 10 s
    bridge = SimSensorBridge(
        node,
        native_hal,
        FRANKA,
        pacer,
        viewer_enabled=False,
        camera_rates_hz=every_camera(0.1),
    )
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        at_setup = spinner.call(set_up_at, bridge, scene)
        assert not scene.render_observations
        hold = native_hal.hold_action()
        for _ in range(20):  # control ticks render nothing
            with bridge.lock:
                native_hal.send_action(hold)
        assert native_hal.read_images() == {}
        frames = {c: probe.wait_count(image_topic(c), 1)[0].msg for c in CAMERAS}
        wait_until(lambda: bridge.frames_published == 2, what="both frames counted")
        assert sorted(renders) == ["agentview", "wrist"]  # one render per frame
        assert bridge.frames_skipped == 0
        spinner.call(bridge.teardown)
    probe.node.destroy_node()
    assert scene.render_observations  # the scene renders its observations again
    expected = scene.render_cameras(at_setup)  # what sim run draws of that state
    for camera, frame in frames.items():
        stamp_s = frame.header.stamp.sec + frame.header.stamp.nanosec * 1e-9
        assert stamp_s == pytest.approx(float(at_setup.time), abs=1e-9) and stamp_s > 0
        assert (frame.height, frame.width) == scene.image_size
        pixels = np.frombuffer(bytes(frame.data), np.uint8).reshape(expected[camera].shape)
        assert pixels.std() > 5  # a picture, not blank
        np.testing.assert_array_equal(pixels, expected[camera])  # pixel for pixel


def test_a_busy_render_thread_skips_frames_and_never_holds_up_the_control_tick(
    ros_context: Context,
    node: Node,
    pacer: Pacer,
    native_hal: SimAttachedHAL,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """While a frame takes forever to render, the cameras' jobs skip (and count) their
    frames and a 100 Hz control tick on the same pacer keeps running."""
    gate = threading.Event()
    patch_update_scene(monkeypatch, lambda camera: assert_open(gate))
    lock = threading.Lock()
    ticks = [0]

    def tick() -> None:
        with lock:
            native_hal.send_action(native_hal.hold_action())
        ticks[0] += 1

    bridge = SimSensorBridge(
        node,
        native_hal,
        FRANKA,
        pacer,
        lock=lock,
        viewer_enabled=False,
        camera_rates_hz=every_camera(50.0),
    )
    try:
        with Spinner(ros_context) as spinner:
            spinner.add_node(node)
            spinner.call(bridge.setup)
            control = pacer.every(0.01, tick, "control")
            wait_until(lambda: bridge.frames_skipped >= 20 and ticks[0] >= 20, what="skips")
            assert bridge.frames_published == 0
            gate.set()
            wait_until(lambda: bridge.frames_published >= 4, what="frames after the stall")
            pacer.cancel(control)
            spinner.call(bridge.teardown)
    finally:
        gate.set()


def assert_open(gate: threading.Event) -> None:
    assert gate.wait(30.0)


def test_native_frames_show_consistent_control_steps_at_the_manifest_rate(
    ros_context: Context, node: Node, pacer: Pacer, native_hal: SimAttachedHAL
) -> None:
    """With a 20 Hz control tick on the same pacer, the cameras publish at their manifest
    10 Hz, each frame stamped with the simulated time of a whole control step."""
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    period = scene.substeps * float(scene.model.opt.timestep)
    probe = Probe(ros_context, {image_topic(c): Image for c in CAMERAS})
    lock = threading.Lock()
    hold = native_hal.hold_action()

    def tick() -> None:
        with lock:
            native_hal.send_action(hold)

    bridge = SimSensorBridge(node, native_hal, FRANKA, pacer, lock=lock, viewer_enabled=False)
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        start_s = float(scene.data.time)
        control = pacer.every(period, tick, "control")
        spinner.call(bridge.setup)
        assert {row.rate_hz for row in bridge.topics()} == {10.0}
        received = probe.wait_count(image_topic("agentview"), 8)
        pacer.cancel(control)
        spinner.call(bridge.teardown)
    probe.node.destroy_node()
    stamps = [r.msg.header.stamp.sec + r.msg.header.stamp.nanosec * 1e-9 for r in received]
    assert stamps == sorted(stamps) and stamps[0] > 0
    steps = [(s - start_s) / period for s in stamps]
    assert all(abs(k - round(k)) < 1e-6 for k in steps), steps  # never mid-step
    rate_hz = (len(received) - 1) / (received[-1].at - received[0].at)
    assert 4.0 < rate_hz < 15.0  # 10 Hz, with room for a loaded two-core machine


def test_a_failing_renderer_stops_the_cameras_not_the_node(
    ros_context: Context,
    node: Node,
    pacer: Pacer,
    native_hal: SimAttachedHAL,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def broken(camera: str) -> None:
        raise RuntimeError("GL context lost")

    patch_update_scene(monkeypatch, broken)
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    before = entity_counts(node, pacer)
    bridge = SimSensorBridge(
        node,
        native_hal,
        FRANKA,
        pacer,
        viewer_enabled=False,
        camera_rates_hz=every_camera(50.0),
    )
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.setup)
        wait_until(lambda: entity_counts(node, pacer)[2] == before[2], what="camera jobs gone")
        with bridge.lock:
            native_hal.send_action(native_hal.hold_action())  # the robot goes on
        assert bridge.frames_published == 0 and bridge.active  # publishers stay
        spinner.call(bridge.teardown)
    assert entity_counts(node, pacer) == before and scene.render_observations
