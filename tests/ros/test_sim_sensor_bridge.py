"""Tests for sim_sensor_bridge.py: per-sensor rates and their override, frames rendered
only when due on the render thread (native scene) or read from the last observation (a HAL
without a scene), stamps, skip counting, teardown. The cameras' jobs run on a real Pacer."""

from __future__ import annotations

import math
from collections.abc import Iterator

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_bridge.pacer import Pacer
from openral_bridge.sim_sensor_bridge import SimSensorBridge
from openral_core.models import RgbSensor, RobotDescription
from openral_core.registry import load_robot_by_id
from openral_hal.protocol import CameraHal, EStopLatch, MujocoBacked
from openral_mujoco.state import FloatArray, JointStateSample
from openral_nodes.runtime import Spinner
from openral_sim.sensor_schedule import sensor_rates
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from tests.ros.ros_helpers import Probe, image_topic, info_topic, wait_until

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone

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


def entity_counts(node: Node, pacer: Pacer) -> tuple[int, int, int]:
    """(timers, publishers) of the node and the pacer's jobs."""
    return len(list(node.timers)), len(list(node.publishers)), len(pacer.jobs)


def job_rates_hz(pacer: Pacer) -> list[float]:
    return sorted(round(1.0 / job.period_s, 6) for job in pacer.jobs)


def test_the_fake_is_a_camera_hal_without_a_scene() -> None:
    hal = FakeSimHal()
    assert isinstance(hal, CameraHal) and isinstance(hal, MujocoBacked)
    assert hal.mujoco_handles() is None


def test_each_camera_publishes_at_its_own_manifest_rate(
    ros_context: Context, node: Node, pacer: Pacer
) -> None:
    description = with_rates(FRANKA, agentview=20.0, wrist=4.0)
    bridge = SimSensorBridge(node, FakeSimHal(), description, pacer, viewer_enabled=False)
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(bridge.setup)
        assert bridge.camera_rates == {"agentview": 20.0, "wrist": 4.0}
        assert job_rates_hz(pacer) == [4.0, 20.0]  # one job per sensor, no node timer
        assert not list(node.timers)
        rates = {row.name: row.rate_hz for row in bridge.topics()}
        assert rates[image_topic("agentview")] == rates[info_topic("agentview")] == 20.0
        assert rates[image_topic("wrist")] == rates[info_topic("wrist")] == 4.0
        wait_until(lambda: spinner.call(bridge.published_counts)["agentview"] >= 15, what="frames")
        counts = spinner.call(bridge.published_counts)
        spinner.call(bridge.teardown)
    assert counts["wrist"] <= counts["agentview"] / 2  # 5x slower, 1 frame each at setup


def test_camera_rate_overrides_every_sensor(node: Node) -> None:
    description = with_rates(FRANKA, agentview=20.0, wrist=4.0)
    pacer = Pacer()  # never started: the jobs are only looked at
    rates = sensor_rates(description, None, frame_rate_hz=15.0)
    bridge = SimSensorBridge(
        node, FakeSimHal(), description, pacer, viewer_enabled=False, camera_rates_hz=rates
    )
    bridge.setup()
    try:
        assert bridge.camera_rates == {"agentview": 15.0, "wrist": 15.0}
        assert {row.rate_hz for row in bridge.topics()} == {15.0}
        assert job_rates_hz(pacer) == [15.0, 15.0]
    finally:
        bridge.teardown()


def test_teardown_removes_every_job_and_publisher(node: Node, pacer: Pacer) -> None:
    before = entity_counts(node, pacer)
    bridge = SimSensorBridge(node, FakeSimHal(), FRANKA, pacer, viewer_enabled=True)
    bridge.setup()
    # an image and a camera_info publisher per camera, a job per camera (the HAL has no
    # MuJoCo model, so no viewer).
    assert entity_counts(node, pacer) == (before[0], before[1] + 4, before[2] + 2)
    bridge.teardown()
    assert entity_counts(node, pacer) == before
    assert not bridge.active and bridge.topics() == []
    bridge.teardown()  # idempotent


def test_without_a_display_the_viewer_is_skipped(
    ros_context: Context, node: Node, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)

    class SimHalWithModel(FakeSimHal):
        def mujoco_handles(self):  # type: ignore[no-untyped-def]

            model = mujoco.MjModel.from_xml_string("<mujoco/>")
            return model, mujoco.MjData(model)

    pacer = Pacer()
    bridge = SimSensorBridge(node, SimHalWithModel(), FRANKA, pacer, viewer_enabled=True)
    bridge.setup()
    try:
        assert bridge._viewer is None
        assert len(pacer.jobs) == 2  # one per camera, no viewer sync job
    finally:
        bridge.teardown()


def test_frames_carry_manifest_frame_ids_sim_time_and_manifest_fovy(
    ros_context: Context, node: Node, pacer: Pacer
) -> None:
    hal = FakeSimHal()
    hal.sim_time_s = 12.5
    probe = Probe(ros_context, {image_topic("wrist"): Image, info_topic("wrist"): CameraInfo})
    rates = sensor_rates(FRANKA, None, frame_rate_hz=20.0)
    bridge = SimSensorBridge(node, hal, FRANKA, pacer, viewer_enabled=False, camera_rates_hz=rates)
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
    assert (image.encoding, image.step) == ("rgb8", SHAPE[1] * 3)
    assert set(bytes(image.data)) == {7}  # the fake's flat frame
    assert info.k[0] == pytest.approx(24.0 / math.tan(math.radians(75.0) / 2))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"camera_rates_hz": {"wrist": 0.0}}, r"camera_rates_hz\['wrist'\]"),
        ({"camera_rates_hz": {"agentview": -2.0}}, r"camera_rates_hz\['agentview'\]"),
        ({"viewer_sync_rate_hz": -1.0}, "viewer_sync_rate_hz"),
    ],
)
def test_bad_rates_are_rejected(node: Node, kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        SimSensorBridge(node, FakeSimHal(), FRANKA, Pacer(), **kwargs)  # type: ignore[arg-type]
