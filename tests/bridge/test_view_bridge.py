"""Tests for view_bridge.py and view_feed.py: what the deploy graph sends to the browser view.

A franka tabletop HAL steps on this thread while a ViewBridge's pacer job feeds a recording
fake of the view: every job sends the live model's data (under the HAL's lock), the manifest
joints and the held action by slot name, at increasing simulated times; a frame the graph
renders reaches the view's camera panel; an observation's frame is sent once however often
it is seen; stopping cancels the job and closes the view once.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import mujoco
import numpy as np
from openral_bridge.pacer import Pacer
from openral_bridge.view_bridge import ViewBridge
from openral_core.loader import load_scene
from openral_hal.factory import HalMode, build_hal
from openral_hal.view_feed import ViewFeed
from openral_sim.scene import scene_robot

from tests.conftest import ROBOTS


class RecordingView:
    """The BrowserView methods ViewFeed calls, remembering each call."""

    def __init__(self) -> None:
        self.poses: list[tuple[float, float]] = []
        self.plots: list[tuple[str, dict[str, float]]] = []
        self.images: list[tuple[str, tuple[int, ...]]] = []
        self.closed = 0

    def pose(self, data: mujoco.MjData, time_s: float) -> bool:
        self.poses.append((time_s, float(data.time)))
        return True

    def plot(self, group: str, values: dict[str, float], time_s: float) -> None:
        self.plots.append((group, dict(values)))

    def image(self, camera: str, rgb: np.ndarray, time_s: float) -> None:
        self.images.append((camera, rgb.shape))

    def depth(self, camera: str, depth_m: np.ndarray, time_s: float) -> None:
        self.images.append((f"{camera}/depth", depth_m.shape))

    def close(self) -> None:
        self.closed += 1


def test_the_bridge_feeds_poses_joints_action_and_frames_then_closes_once() -> None:
    scene = load_scene(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    hal = build_hal(scene_robot(scene, None), mode=HalMode.SIM, scene=scene)
    hal.connect()
    view, lock, pacer = RecordingView(), threading.Lock(), Pacer()
    bridge = ViewBridge(hal, ViewFeed(view, hal), lock, rate_hz=50.0)  # type: ignore[arg-type]
    try:
        bridge.start(pacer)
        pacer.start()
        hold = hal.hold_action()
        for _ in range(40):
            with lock:
                hal.send_action(hold)
            time.sleep(0.01)
        bridge.frame("wrist", np.zeros((128, 128, 3), np.uint8), 0.5)
        names, slots = list(hal.read_state().names), list(hal.action_names)
    finally:
        bridge.stop()
        bridge.stop()
        pacer.stop()
        hal.disconnect()
    assert len(view.poses) >= 5, view.poses
    assert all(t == sim for t, sim in view.poses)  # the live data, at its own time
    times = [t for t, _ in view.poses]
    assert times == sorted(times) and times[-1] > times[0]
    joints = [values for group, values in view.plots if group == "joints"]
    actions = [values for group, values in view.plots if group == "action"]
    assert list(joints[-1]) == names
    assert list(actions[-1]) == slots
    assert np.allclose(list(actions[-1].values()), hold)
    assert ("wrist", (128, 128, 3)) in view.images
    assert view.closed == 1


def test_an_observations_frame_is_sent_once() -> None:
    class Observing:
        """A HAL whose last observation keeps handing out the same frame."""

        action_names = ("a",)
        frame = np.ones((4, 4, 3), np.uint8)

        def read_state(self) -> Any:
            return type("State", (), {"sim_time_s": 1.0, "names": ("a",), "positions": np.zeros(1)})

        def last_observation(self) -> Any:
            return type("Obs", (), {"images": {"cam": self.frame}, "depth": {}})

    view = RecordingView()
    hal = Observing()
    feed = ViewFeed(view, hal)  # type: ignore[arg-type]
    from openral_hal import view_feed

    original = view_feed.ObservingHal
    view_feed.ObservingHal = Observing  # type: ignore[misc]  # the protocol check, for the fake
    try:
        for _ in range(3):
            feed()
        hal.frame = np.ones((4, 4, 3), np.uint8)  # a new frame
        feed()
    finally:
        view_feed.ObservingHal = original  # type: ignore[misc]
    assert [camera for camera, _ in view.images] == ["cam", "cam"]
    assert view.poses == []  # no MuJoCo model: nothing to pose
