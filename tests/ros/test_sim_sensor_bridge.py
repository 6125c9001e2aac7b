"""Tests for sim_sensor_bridge.py: per-sensor rates and their override, frames rendered
only when due on the render thread (native scene) or read from the last observation (a HAL
without a scene), stamps, skip counting, teardown."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from functools import partial

import numpy as np
import numpy.typing as npt
import pytest
from openral_bridge.sim_sensor_bridge import SimSensorBridge
from openral_core import load_scene, open_robot_by_id
from openral_core.models import RgbSensor, RobotDescription
from openral_core.registry import load_robot_by_id
from openral_hal.factory import build_hal
from openral_hal.protocol import CameraHal, EStopLatch, MujocoBacked
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.state import FloatArray, JointStateSample
from openral_nodes.runtime import Spinner
from openral_sim.native_scene import NativeScene
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from tests.ros.ros_helpers import FRANKA_SCENE, Probe, image_topic, info_topic, wait_until

FRANKA = load_robot_by_id("franka_panda")
SHAPE = (48, 64, 3)
CAMERAS = ("agentview", "wrist")


class FakeSimHal(EStopLatch):
    """A simulated HAL of one joint "j" without a scene: renders the franka cameras as
    flat images in its "last observation"."""

    is_real = False
    description = FRANKA
    joint_names = action_names = ("j",)
    connected = True

    def __init__(self) -> None:
        self.sim_time_s = 0.0

    def connect(self) -> None:
        pass

    def disconnect(self) -> None:
        pass

    def hold_action(self) -> FloatArray:
        return np.zeros(1)

    def send_action(self, action: object) -> None:
        self._refuse_when_estopped()

    def read_images(self) -> dict[str, npt.NDArray[np.uint8]]:
        return {name: np.full(SHAPE, 7, np.uint8) for name in CAMERAS}

    def camera_fovy_deg(self, sensor: str) -> float | None:
        return None  # no scene camera: the manifest's fovy_deg is used

    def read_state(self) -> JointStateSample:
        zeros = np.zeros(1)
        return JointStateSample(("j",), zeros, zeros, zeros, 0, sim_time_s=self.sim_time_s)

    def mujoco_handles(self) -> None:
        return None


def with_rates(description: RobotDescription, **rates: float) -> RobotDescription:
    """``description`` with some RGB sensors' ``rate_hz`` changed [Hz]."""
    sensors = [
        s.model_copy(update={"rate_hz": rates[s.name]})
        if isinstance(s, RgbSensor) and s.name in rates
        else s
        for s in description.sensors
    ]
    return description.model_copy(update={"sensors": sensors})


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("bridge_test_node", context=ros_context)
    yield node
    node.destroy_node()


def entity_counts(node: Node) -> tuple[int, int]:
    return len(list(node.timers)), len(list(node.publishers))


def timer_rates_hz(node: Node) -> list[float]:
    return sorted(round(1e9 / t.timer_period_ns, 6) for t in node.timers)


def test_the_fake_is_a_camera_hal_without_a_scene() -> None:
    hal = FakeSimHal()
    assert isinstance(hal, CameraHal) and isinstance(hal, MujocoBacked)
    assert hal.mujoco_handles() is None


def test_each_camera_publishes_at_its_own_manifest_rate(ros_context: Context, node: Node) -> None:
    description = with_rates(FRANKA, agentview=20.0, wrist=4.0)
    bridge = SimSensorBridge(node, FakeSimHal(), description, viewer_enabled=False)
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.setup)
        assert bridge.camera_rates == {"agentview": 20.0, "wrist": 4.0}
        assert timer_rates_hz(node) == [4.0, 20.0]  # one timer per sensor
        rates = {row.name: row.rate_hz for row in bridge.topics()}
        assert rates[image_topic("agentview")] == rates[info_topic("agentview")] == 20.0
        assert rates[image_topic("wrist")] == rates[info_topic("wrist")] == 4.0
        wait_until(lambda: spinner.call(bridge.published_counts)["agentview"] >= 15, what="frames")
        counts = spinner.call(bridge.published_counts)
        spinner.call(bridge.teardown)
    assert counts["wrist"] <= counts["agentview"] / 2  # 5x slower, 1 frame each at setup


def test_camera_rate_overrides_every_sensor(ros_context: Context, node: Node) -> None:
    description = with_rates(FRANKA, agentview=20.0, wrist=4.0)
    bridge = SimSensorBridge(
        node, FakeSimHal(), description, viewer_enabled=False, camera_rate_hz=15.0
    )
    bridge.setup()
    try:
        assert bridge.camera_rates == {"agentview": 15.0, "wrist": 15.0}
        assert {row.rate_hz for row in bridge.topics()} == {15.0}
        assert timer_rates_hz(node) == [15.0, 15.0]
    finally:
        bridge.teardown()


def test_teardown_removes_every_timer_and_publisher(ros_context: Context, node: Node) -> None:
    before = entity_counts(node)
    bridge = SimSensorBridge(node, FakeSimHal(), FRANKA, viewer_enabled=True)
    bridge.setup()
    # an image and a camera_info publisher per camera, a timer per camera (the HAL has no
    # MuJoCo model, so no viewer).
    assert entity_counts(node) == (before[0] + 2, before[1] + 4)
    bridge.teardown()
    assert entity_counts(node) == before
    assert not bridge.active and bridge.topics() == []
    bridge.teardown()  # idempotent


def test_without_a_display_the_viewer_is_skipped(
    ros_context: Context, node: Node, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)

    class SimHalWithModel(FakeSimHal):
        def mujoco_handles(self):  # type: ignore[no-untyped-def]
            import mujoco

            model = mujoco.MjModel.from_xml_string("<mujoco/>")
            return model, mujoco.MjData(model)

    bridge = SimSensorBridge(node, SimHalWithModel(), FRANKA, viewer_enabled=True)
    bridge.setup()
    try:
        assert bridge._viewer is None
        assert len(list(node.timers)) == 2  # one per camera, no viewer sync timer
    finally:
        bridge.teardown()


def test_frames_carry_manifest_frame_ids_sim_time_and_manifest_fovy(
    ros_context: Context, node: Node
) -> None:
    hal = FakeSimHal()
    hal.sim_time_s = 12.5
    probe = Probe(ros_context, {image_topic("wrist"): Image, info_topic("wrist"): CameraInfo})
    bridge = SimSensorBridge(node, hal, FRANKA, viewer_enabled=False, camera_rate_hz=20.0)
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        spinner.call(bridge.setup)
        image = probe.wait_count(image_topic("wrist"), 1)[0].msg
        info = probe.wait_count(info_topic("wrist"), 1)[0].msg
        spinner.call(bridge.teardown)
    probe.node.destroy_node()
    assert image.header.frame_id == info.header.frame_id == "wrist_optical_frame"
    assert image.header.stamp.sec >= 12  # simulated time, not wall-clock time
    assert (image.height, image.width) == SHAPE[:2]
    assert info.k[0] == pytest.approx(24.0 / math.tan(math.radians(75.0) / 2))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"camera_rate_hz": 0.0}, "camera_rate_hz"),
        ({"camera_rate_hz": -2.0}, "camera_rate_hz"),
        ({"viewer_sync_rate_hz": -1.0}, "viewer_sync_rate_hz"),
    ],
)
def test_bad_rates_are_rejected(node: Node, kwargs: dict[str, float], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        SimSensorBridge(node, FakeSimHal(), FRANKA, **kwargs)  # type: ignore[arg-type]


# -- a native scene: rendered on demand, on the render thread --------------------------------


@pytest.fixture(scope="module")
def native_hal() -> Iterator[SimAttachedHAL]:
    hal = build_hal(open_robot_by_id("franka_panda"), mode="sim", scene=load_scene(FRANKA_SCENE))
    assert isinstance(hal, SimAttachedHAL) and isinstance(hal.env, NativeScene)
    hal.connect()
    yield hal
    hal.disconnect()


@pytest.fixture
def renders(native_hal: SimAttachedHAL) -> Iterator[list[tuple[str, ...]]]:
    """Every ``render_cameras`` call of the scene: the sensors it rendered."""
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    calls: list[tuple[str, ...]] = []
    original = scene.render_cameras

    def counted(data, sensors=None, renderer=None):  # type: ignore[no-untyped-def]
        calls.append(tuple(sensors or scene.camera_names))
        return original(data, sensors, renderer)

    scene.render_cameras = counted  # type: ignore[method-assign]
    yield calls
    scene.render_cameras = original  # type: ignore[method-assign]


def set_up_at(bridge: SimSensorBridge, scene: NativeScene) -> float:
    """Set the bridge up and return the simulated time it did so at [s]."""
    bridge.setup()
    return float(scene.data.time)


def test_a_native_scene_renders_a_frame_only_when_one_is_due(
    ros_context: Context, node: Node, native_hal: SimAttachedHAL, renders: list[tuple[str, ...]]
) -> None:
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    probe = Probe(ros_context, {image_topic(c): Image for c in CAMERAS})
    # 0.1 Hz: after the one frame per camera at setup, nothing is due for 10 s
    bridge = SimSensorBridge(node, native_hal, FRANKA, viewer_enabled=False, camera_rate_hz=0.1)
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        sim_time_at_setup = spinner.call(set_up_at, bridge, scene)
        assert not scene.render_observations
        hold = native_hal.hold_action()
        for _ in range(20):  # control ticks render nothing
            spinner.call(native_hal.send_action, hold)
        assert native_hal.read_images() == {}
        frames = {c: probe.wait_count(image_topic(c), 1)[0].msg for c in CAMERAS}
        wait_until(lambda: bridge.frames_published == 2, what="both frames counted")
        assert sorted(renders) == [("agentview",), ("wrist",)]  # one render per frame
        assert bridge.frames_skipped == 0
        spinner.call(bridge.teardown)
    probe.node.destroy_node()
    assert scene.render_observations  # the scene renders its observations again
    for frame in frames.values():
        stamp_s = frame.header.stamp.sec + frame.header.stamp.nanosec * 1e-9
        assert stamp_s == pytest.approx(sim_time_at_setup, abs=1e-9) and stamp_s > 0
        assert (frame.height, frame.width) == scene.image_size
        assert np.frombuffer(bytes(frame.data), np.uint8).std() > 5  # a picture, not blank


def test_a_busy_render_thread_skips_frames_and_never_holds_up_the_executor(
    ros_context: Context, node: Node, native_hal: SimAttachedHAL
) -> None:
    """While a frame takes forever to render, the cameras' timers skip (and count) their
    frames and a 100 Hz control tick on the same executor keeps running."""
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    gate = threading.Event()
    original = scene.render_cameras

    def slow(data, sensors=None, renderer=None):  # type: ignore[no-untyped-def]
        assert gate.wait(30.0)
        return original(data, sensors, renderer)

    ticks = [0]

    def tick() -> None:
        native_hal.send_action(native_hal.hold_action())
        ticks[0] += 1

    bridge = SimSensorBridge(node, native_hal, FRANKA, viewer_enabled=False, camera_rate_hz=50.0)
    scene.render_cameras = slow  # type: ignore[method-assign]
    try:
        with Spinner(ros_context) as spinner:
            spinner.add_node(node)
            spinner.call(bridge.setup)
            control = spinner.call(node.create_timer, 0.01, tick)
            wait_until(lambda: bridge.frames_skipped >= 20 and ticks[0] >= 20, what="skips")
            assert bridge.frames_published == 0
            gate.set()
            wait_until(lambda: bridge.frames_published >= 4, what="frames after the stall")
            spinner.call(node.destroy_timer, control)
            spinner.call(bridge.teardown)
    finally:
        gate.set()
        scene.render_cameras = original  # type: ignore[method-assign]


def test_native_frames_show_consistent_control_steps_at_the_manifest_rate(
    ros_context: Context, node: Node, native_hal: SimAttachedHAL
) -> None:
    """With a 20 Hz control tick on the same executor, the cameras publish at their
    manifest 10 Hz, each frame stamped with the simulated time of a whole control step."""
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    period = scene.substeps * float(scene.model.opt.timestep)
    probe = Probe(ros_context, {image_topic(c): Image for c in CAMERAS})
    bridge = SimSensorBridge(node, native_hal, FRANKA, viewer_enabled=False)
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        start_s = spinner.call(lambda: float(scene.data.time))
        hold = native_hal.hold_action()
        control = spinner.call(node.create_timer, period, partial(native_hal.send_action, hold))
        spinner.call(bridge.setup)
        assert {row.rate_hz for row in bridge.topics()} == {10.0}
        received = probe.wait_count(image_topic("agentview"), 8)
        spinner.call(node.destroy_timer, control)
        spinner.call(bridge.teardown)
    probe.node.destroy_node()
    stamps = [r.msg.header.stamp.sec + r.msg.header.stamp.nanosec * 1e-9 for r in received]
    assert stamps == sorted(stamps) and stamps[0] > 0
    steps = [(s - start_s) / period for s in stamps]
    assert all(abs(k - round(k)) < 1e-6 for k in steps), steps  # never mid-step
    rate_hz = (len(received) - 1) / (received[-1].at - received[0].at)
    assert 4.0 < rate_hz < 15.0  # 10 Hz, with room for a loaded two-core machine


def test_a_failing_renderer_stops_the_cameras_not_the_node(
    ros_context: Context, node: Node, native_hal: SimAttachedHAL
) -> None:
    scene = native_hal.env
    assert isinstance(scene, NativeScene)
    original = scene.render_cameras

    def broken(data, sensors=None, renderer=None):  # type: ignore[no-untyped-def]
        raise RuntimeError("GL context lost")

    before = entity_counts(node)
    bridge = SimSensorBridge(node, native_hal, FRANKA, viewer_enabled=False, camera_rate_hz=50.0)
    scene.render_cameras = broken  # type: ignore[method-assign]
    try:
        with Spinner(ros_context) as spinner:
            spinner.add_node(node)
            spinner.call(bridge.setup)
            wait_until(lambda: spinner.call(entity_counts, node)[0] == before[0], what="timers")
            spinner.call(native_hal.send_action, native_hal.hold_action())  # the robot goes on
            assert bridge.frames_published == 0 and bridge.active  # publishers stay
            spinner.call(bridge.teardown)
    finally:
        scene.render_cameras = original  # type: ignore[method-assign]
    assert entity_counts(node) == before and scene.render_observations
