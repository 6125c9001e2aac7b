"""Tests for frame_renderer.py: snapshots render the state they were taken at, on a thread
of their own that never reads the live data; a busy camera is skipped, never queued."""

from __future__ import annotations

import os
import statistics
import threading
import time
from collections.abc import Callable, Iterator

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_bridge.frame_renderer import RETRY_S, FrameRenderer, renderers_opened
from openral_sim.mujoco_capture import MujocoCapture, _Developer
from openral_sim.native_scene import NativeScene
from openral_sim.scene import build_sim_env_from_yaml

from tests.conftest import ROBOTS

Image = npt.NDArray[np.uint8]
TINY = """
<mujoco>
  <worldbody>
    <camera name="cam" pos="0 -1 0.2" xyaxes="1 0 0 0 0 1"/>
    <body name="ball"><freejoint/><geom size="0.1"/></body>
  </worldbody>
</mujoco>
"""
WAIT_S = 15.0


class Published:
    """Collects (sensor, image, sim time) from the render thread."""

    def __init__(self) -> None:
        self.frames: list[tuple[str, Image, float]] = []
        self.condition = threading.Condition()

    def __call__(self, sensor: str, image: Image, sim_time_s: float) -> None:
        with self.condition:
            self.frames.append((sensor, image, sim_time_s))
            self.condition.notify_all()

    def wait(self, count: int) -> list[tuple[str, Image, float]]:
        with self.condition:
            assert self.condition.wait_for(lambda: len(self.frames) >= count, WAIT_S)
            return list(self.frames)


class Gate:
    """A render function that blocks until opened (a render that takes its time)."""

    def __init__(self) -> None:
        self.open = threading.Event()
        self.entered = threading.Semaphore(0)
        self.data_seen: list[mujoco.MjData] = []

    def __call__(self, renderer: mujoco.Renderer, data: mujoco.MjData, sensor: str) -> Image:
        self.data_seen.append(data)
        self.entered.release()
        assert self.open.wait(WAIT_S)
        return np.full((4, 4, 3), int(data.time * 10) % 256, np.uint8)


@pytest.fixture
def tiny() -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(TINY)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data)
    return model, data


def make(
    handles: tuple[mujoco.MjModel, mujoco.MjData],
    render: Callable[[mujoco.Renderer, mujoco.MjData, str], Image],
    sensors: tuple[str, ...] = ("a", "b"),
    size: tuple[int, int] = (16, 16),
) -> tuple[FrameRenderer, Published]:
    published = Published()
    frames = FrameRenderer(MujocoCapture(*handles, sensors, size, render), published)
    frames.start()
    return frames, published


def test_a_busy_camera_is_skipped_and_counted_never_queued(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    gate = Gate()
    frames, published = make(tiny, gate)
    try:
        assert frames.request("a")
        assert gate.entered.acquire(timeout=WAIT_S)  # "a" is rendering now
        assert [frames.request("a") for _ in range(3)] == [False] * 3
        assert frames.request("b")  # another camera has its own slot
        assert not frames.request("b")  # ... which is now taken until "b" is published
        assert frames.skipped == {"a": 3, "b": 1}
        gate.open.set()
        published.wait(2)
        time.sleep(0.2)  # nothing else was queued: no third frame comes
        assert [sensor for sensor, _, _ in published.frames] == ["a", "b"]
        assert frames.rendered == {"a": 1, "b": 1}
        assert frames.request("a")  # free again once published
        published.wait(3)
    finally:
        gate.open.set()
        assert frames.stop()
    assert not frames.running


def test_a_request_that_may_wait_gets_its_frame_after_the_one_in_flight(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    gate = Gate()
    frames, published = make(tiny, gate)
    try:
        assert frames.request("a")
        assert gate.entered.acquire(timeout=WAIT_S)  # "a" is rendering now
        assert not frames.request("a", wait_s=0.05)  # still in flight when the wait ends
        threading.Timer(0.1, gate.open.set).start()
        assert frames.request("a", wait_s=WAIT_S)  # after the reset: this frame must come
        assert [sensor for sensor, _, _ in published.wait(2)] == ["a", "a"]
        assert frames.skipped == {"a": 1, "b": 0}
    finally:
        gate.open.set()
        assert frames.stop()


def test_the_render_thread_never_reads_the_live_data(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    model, live = tiny
    gate = Gate()
    frames, published = make(tiny, gate, ("a",))
    try:
        taken_at = float(live.time)
        assert frames.request("a")
        assert gate.entered.acquire(timeout=WAIT_S)
        for _ in range(50):  # the control loop goes on while the frame renders
            mujoco.mj_step(model, live)
        gate.open.set()
        ((_, _, stamp),) = published.wait(1)
    finally:
        gate.open.set()
        frames.stop()
    assert gate.data_seen and all(data is not live for data in gate.data_seen)
    assert stamp == taken_at > 0  # the snapshot's simulated time, not the live one
    assert live.time > taken_at


def test_request_only_copies_while_a_frame_renders(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    gate = Gate()
    frames, _ = make(tiny, gate, ("a", "b"))
    try:
        frames.request("a")
        assert gate.entered.acquire(timeout=WAIT_S)
        durations = []
        for _ in range(200):
            start = time.perf_counter()
            frames.request("b")  # the first queues a copy, the rest are skipped
            durations.append(time.perf_counter() - start)
        assert statistics.median(durations) < 2e-4  # [s]; a render takes milliseconds
        assert frames.skipped["b"] == 199
    finally:
        gate.open.set()
        frames.stop()


def test_a_paced_request_asks_for_a_retry_only_while_its_frame_is_in_flight(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    gate, lock = Gate(), threading.Lock()
    frames, published = make(tiny, gate)
    try:
        assert frames.request_or_retry("a", lock) is None  # queued
        assert gate.entered.acquire(timeout=WAIT_S)
        assert frames.request_or_retry("a", lock) == RETRY_S  # in flight: ask again soon
        assert not lock.locked()  # held only for the request
        gate.open.set()
        published.wait(1)
        frames.error = RuntimeError("GL exploded")
        assert frames.request_or_retry("a", lock) is None  # failed: no retry, ever
    finally:
        gate.open.set()
        assert frames.stop()


def test_a_failing_render_stops_the_thread_and_is_reported(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    def broken(renderer: mujoco.Renderer, data: mujoco.MjData, sensor: str) -> Image:
        raise RuntimeError("GL exploded")

    frames, published = make(tiny, broken)
    frames.request("a")
    deadline = time.monotonic() + WAIT_S
    while frames.error is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert isinstance(frames.error, RuntimeError)
    assert not frames.request("b") and not frames.running
    assert frames.stop() and not published.frames


def test_unknown_sensors_are_refused(tiny: tuple[mujoco.MjModel, mujoco.MjData]) -> None:
    frames = FrameRenderer(MujocoCapture(*tiny, ("a",), (16, 16), Gate()), Published())
    with pytest.raises(KeyError):
        frames.request("z")
    assert frames.stop()  # never started: nothing to stop


@pytest.fixture(scope="module")
def franka() -> Iterator[NativeScene]:
    scene = build_sim_env_from_yaml(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    assert isinstance(scene, NativeScene)
    scene.render_observations = False
    scene.reset(0)
    try:
        yield scene
    finally:
        scene.close()


def test_a_snapshot_frame_is_the_frame_of_the_state_it_was_taken_at(
    franka: NativeScene,
) -> None:
    """Rendered on its thread from a snapshot while the live scene moves on, the frame is
    pixel for pixel the scene's own render of the live data at the request (what
    ``sim run`` writes for that step), and differs from the live scene's frame after."""
    model, live = franka.mujoco_handles()
    gate = threading.Event()

    def render(renderer: mujoco.Renderer, data: mujoco.MjData, sensor: str) -> Image:
        assert gate.wait(WAIT_S)
        return franka.render_cameras(data, (sensor,), renderer)[sensor]

    arm = np.r_[np.ones(7), 0.0]  # the seven arm joints [rad]; the gripper stays
    hold = franka.hold_action()
    for _ in range(4):
        franka.step(hold + 0.3 * arm)
    expected = franka.render_cameras(live, ("wrist",))["wrist"]
    taken_at = float(live.time)
    frames, published = make((model, live), render, ("wrist",), franka.image_size)
    try:
        assert frames.request("wrist")
        for _ in range(4):
            franka.step(hold - 0.3 * arm)
        gate.set()
        ((_, image, stamp),) = published.wait(1)
    finally:
        gate.set()
        assert frames.stop()
    np.testing.assert_array_equal(image, expected)
    assert stamp == taken_at > 0
    moved = franka.render_cameras(live, ("wrist",))["wrist"]
    assert np.abs(moved.astype(int) - image.astype(int)).mean() > 1.0


def test_without_observation_rendering_step_renders_nothing(franka: NativeScene) -> None:
    calls: list[object] = []
    original = franka.sensors.render
    franka.sensors.render = lambda *a, **k: calls.append(a) or original(*a, **k)  # type: ignore[method-assign]
    try:
        obs = franka.step(franka.hold_action()).obs
        assert obs.images == {} and obs.time_s > 0 and not calls
        franka.render_observations = True
        obs = franka.step(franka.hold_action()).obs
        assert set(obs.images) == {"agentview", "wrist"} and len(calls) == 1
    finally:
        franka.sensors.render = original  # type: ignore[method-assign]
        franka.render_observations = False
    assert franka.image_size == (128, 128)
    with pytest.raises(KeyError, match="belly"):
        franka.render_cameras(franka.data, ("belly",))


class SlowOpening(MujocoCapture[Image]):
    """A capture whose renderer is made once ``gate`` opens (or fails to be, ``fail``)."""

    def __init__(self, handles: tuple[mujoco.MjModel, mujoco.MjData], fail: bool) -> None:
        super().__init__(*handles, ("a",), (16, 16), lambda r, d, s: np.zeros((1, 1, 3), np.uint8))
        self.gate, self.fail = threading.Event(), fail

    def open(self) -> _Developer[Image]:
        assert self.gate.wait(WAIT_S)
        if self.fail:
            raise RuntimeError("no GL context")
        return super().open()


def test_renderers_opened_waits_until_every_started_renderer_is_made_or_failed(
    tiny: tuple[mujoco.MjModel, mujoco.MjData],
) -> None:
    made, failing = SlowOpening(tiny, fail=False), SlowOpening(tiny, fail=True)
    renderers = [FrameRenderer(made, Published()), FrameRenderer(failing, Published())]
    for renderer in renderers:
        renderer.start()
    try:
        assert not renderers_opened(0.1)
        made.gate.set()
        assert not renderers_opened(0.1)  # the other is still being made
        failing.gate.set()
        assert renderers_opened(WAIT_S)  # one that failed is no longer being made
        assert renderers[0].running and isinstance(renderers[1].error, RuntimeError)
    finally:
        made.gate.set()
        failing.gate.set()
        assert all(renderer.stop() for renderer in renderers)
