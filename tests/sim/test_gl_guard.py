"""gl_guard.py: the RGB cameras' and a depth camera's developers, each on its own thread
as ``deploy sim`` runs them, never render at the same time (one OpenGL render at a time in
a process), and both keep rendering."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import mujoco
import pytest
from openral_core import open_robot_by_id
from openral_core.loader import load_scene
from openral_sim.native_scene import NativeScene
from openral_sim.sensor_sources import FrameCapture

from tests.conftest import ROBOTS

FRANKA_SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
RUN_S = 1.5
"""How long each thread keeps rendering [s]."""


class _Overlap:
    """Counts renders in progress and the most seen at once."""

    def __init__(self, render: Callable[..., object]) -> None:
        self._render, self._lock = render, threading.Lock()
        self.now = self.most = 0

    def render(self, renderer: mujoco.Renderer, *args: object, **kwargs: object) -> object:
        """Stands in for ``mujoco.Renderer.render``."""
        with self._lock:
            self.now += 1
            self.most = max(self.most, self.now)
        try:
            time.sleep(0.002)  # widen the window a second render would have to overlap
            return self._render(renderer, *args, **kwargs)
        finally:
            with self._lock:
                self.now -= 1


def _develop_for(capture: FrameCapture[object], sensor: str, frames: list[int]) -> None:
    developer = capture.open()
    try:
        end = time.monotonic() + RUN_S
        while time.monotonic() < end:
            capture.snapshot(sensor)
            developer.develop(sensor)
            frames.append(1)
    finally:
        developer.close()


def test_camera_and_depth_threads_never_render_at_once(monkeypatch: pytest.MonkeyPatch) -> None:
    scene = NativeScene(load_scene(FRANKA_SCENE), open_robot_by_id("franka_panda"))
    scene.reset(0)
    overlap = _Overlap(mujoco.Renderer.render)

    def render(renderer: mujoco.Renderer, *args: object, **kwargs: object) -> object:
        return overlap.render(renderer, *args, **kwargs)

    monkeypatch.setattr(mujoco.Renderer, "render", render)
    camera, depth = scene.sensors.camera_capture(), scene.sensors.depth_capture("front_depth")
    rgb_frames: list[int] = []
    depth_frames: list[int] = []
    threads = [
        threading.Thread(target=_develop_for, args=(camera, camera.sensors[0], rgb_frames)),
        threading.Thread(target=_develop_for, args=(depth, "front_depth", depth_frames)),
    ]
    try:
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        scene.close()
    assert len(rgb_frames) >= 2 and len(depth_frames) >= 2
    assert overlap.most == 1
