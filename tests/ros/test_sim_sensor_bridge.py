"""Tests for sim_sensor_bridge.py against fake HALs: gating, the fault guard, teardown."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import numpy.typing as npt
import pytest
from openral_bridge.sim_sensor_bridge import SimSensorBridge
from openral_core.registry import load_robot_by_id
from openral_hal.protocol import CameraHal, EStopLatch, IdleSteppable, MujocoBacked
from openral_mujoco.state import FloatArray, JointStateSample
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from tests.ros.ros_helpers import Probe, image_topic, info_topic, wait_until

FRANKA = load_robot_by_id("franka_panda")
SHAPE = (48, 64, 3)


class FakeSimHal(EStopLatch):
    """A whole simulated HAL (RobotHal, CameraHal, IdleSteppable, MujocoBacked) of one joint
    "j": renders the franka cameras as flat images; idle_step can be made to fail."""

    is_real = False
    description = FRANKA
    joint_names = action_names = ("j",)
    connected = True

    def __init__(self, fail_idle: bool = False) -> None:
        self.fail_idle = fail_idle
        self.last_action_ns = 0
        self.idle_calls = 0
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
        return {name: np.full(SHAPE, 7, np.uint8) for name in ("agentview", "wrist")}

    def camera_fovy_deg(self, sensor: str) -> float | None:
        return None  # no scene camera: the manifest's fovy_deg is used

    def read_state(self) -> JointStateSample:
        zeros = np.zeros(1)
        return JointStateSample(("j",), zeros, zeros, zeros, 0, sim_time_s=self.sim_time_s)

    def idle_step(self) -> bool:
        self.idle_calls += 1
        if self.fail_idle:
            raise RuntimeError("backend exploded")
        self.sim_time_s += 0.05
        return True

    def mujoco_handles(self) -> None:
        return None


class FakeRealHal(FakeSimHal):
    """A real robot that (wrongly) offers idle_step: the bridge must never call it."""

    is_real = True


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("bridge_test_node", context=ros_context)
    yield node
    node.destroy_node()


def entity_counts(node: Node) -> tuple[int, int]:
    return len(list(node.timers)), len(list(node.publishers))


def test_a_failing_idle_step_is_reported_once_and_the_stepper_removed(
    ros_context: Context, node: Node
) -> None:
    hal = FakeSimHal(fail_idle=True)
    bridge = SimSensorBridge(node, hal, FRANKA, viewer_enabled=False, camera_rate_hz=20.0)
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.setup)
        assert bridge.idle_stepping
        wait_until(lambda: spinner.call(lambda: not bridge.idle_stepping), what="guard to trip")
        published = spinner.call(lambda: bridge.frames_published)
        wait_until(
            lambda: spinner.call(lambda: bridge.frames_published) >= published + 3,
            what="cameras to keep publishing after the fault",
        )
        assert hal.idle_calls == 1
        spinner.call(bridge.teardown)


def test_the_fake_is_a_whole_simulated_hal() -> None:
    hal = FakeSimHal()
    assert isinstance(hal, CameraHal) and isinstance(hal, IdleSteppable)
    assert isinstance(hal, MujocoBacked)


def test_no_idle_stepper_for_a_real_hal(ros_context: Context, node: Node) -> None:
    hal = FakeRealHal()
    bridge = SimSensorBridge(node, hal, FRANKA, viewer_enabled=False, camera_rate_hz=20.0)
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.setup)
        assert not bridge.idle_stepping
        wait_until(lambda: spinner.call(lambda: bridge.frames_published) >= 3, what="frames")
        assert hal.idle_calls == 0
        spinner.call(bridge.teardown)


def test_idle_stepper_waits_out_the_hold_after_an_action(ros_context: Context, node: Node) -> None:
    import time

    hal = FakeSimHal()
    hal.last_action_ns = time.monotonic_ns() + 10**12  # an action "now" for the next ~17 min
    bridge = SimSensorBridge(node, hal, FRANKA, viewer_enabled=False, camera_rate_hz=20.0)
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.setup)
        wait_until(lambda: spinner.call(lambda: bridge.frames_published) >= 4, what="frames")
        assert hal.idle_calls == 0
        hal.last_action_ns = 0  # quiet again
        wait_until(lambda: hal.idle_calls >= 2, what="idle steps once quiet")
        spinner.call(bridge.teardown)


def test_teardown_removes_every_timer_and_publisher(ros_context: Context, node: Node) -> None:
    before = entity_counts(node)
    bridge = SimSensorBridge(node, FakeSimHal(), FRANKA, viewer_enabled=True)
    bridge.setup()
    # an image and a camera_info publisher per camera; camera and idle timers (the HAL has
    # no MuJoCo model, so no viewer).
    assert entity_counts(node) == (before[0] + 2, before[1] + 4)
    bridge.teardown()
    assert entity_counts(node) == before
    assert not bridge.active
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
        assert len(list(node.timers)) == 2  # camera + idle stepper, no viewer sync timer
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
        ({"viewer_sync_rate_hz": -1.0}, "viewer_sync_rate_hz"),
        ({"idle_hold_ms": -5.0}, "idle_hold_ms"),
    ],
)
def test_bad_rates_are_rejected(node: Node, kwargs: dict[str, float], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        SimSensorBridge(node, FakeSimHal(), FRANKA, **kwargs)  # type: ignore[arg-type]
