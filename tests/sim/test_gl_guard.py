"""gl_guard.py: the RGB cameras' and a depth camera's developers, each on its own thread
as ``deploy sim`` runs them, never render at the same time (one OpenGL render at a time in
a process), and both keep rendering."""

from __future__ import annotations

import multiprocessing
import threading
import time
from collections.abc import Callable

import mujoco
import pytest
from openral_core import open_robot_by_id
from openral_core.loader import load_scene
from openral_sim.gl_guard import InheritedGlError, close_renderer, open_renderer
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


_SMALL = '<mujoco><worldbody><geom type="box" size=".1 .1 .1"/></worldbody></mujoco>'


def _render_in_child(queue: multiprocessing.Queue[str]) -> None:
    model = mujoco.MjModel.from_xml_string(_SMALL)
    try:
        close_renderer(open_renderer(model, 32, 32))
        queue.put("rendered")
    except InheritedGlError as error:
        queue.put(str(error))


def test_a_process_forked_after_opening_gl_refuses_to_render_instead_of_hanging() -> None:
    """Measured without the guard: the child's first renderer waits forever (both with
    the parent's renderer still open and closed)."""
    close_renderer(open_renderer(mujoco.MjModel.from_xml_string(_SMALL), 32, 32))
    fork = multiprocessing.get_context("fork")
    queue: multiprocessing.Queue[str] = fork.Queue()
    child = fork.Process(target=_render_in_child, args=(queue,))
    child.start()
    try:
        said = queue.get(timeout=30)
    finally:
        child.join(5)
        if child.is_alive():
            child.kill()
    assert "was forked from process" in said and "'forkserver'" in said, said
    assert said.count("\n") == 0
    fresh = multiprocessing.get_context("forkserver")
    queue = fresh.Queue()
    child = fresh.Process(target=_render_in_child, args=(queue,))
    child.start()
    try:
        assert queue.get(timeout=60) == "rendered"
    finally:
        child.join(5)


def test_a_scene_rendered_on_one_thread_renders_on_another() -> None:
    """A bus emulator's scene is reset (and rendered) on the thread that built it, then
    stepped by the emulator's own thread: measured without the release, the second
    thread's render failed with EGL_BAD_ACCESS (the context was still current on the
    first)."""
    scene = NativeScene(load_scene(FRANKA_SCENE), open_robot_by_id("franka_panda"))
    try:
        scene.reset(0)
        camera = next(iter(scene.sensors.cameras))
        here = scene.sensors.render(scene.data, [camera])[camera]
        there: list[object] = []

        def render_elsewhere() -> None:
            try:
                there.append(scene.sensors.render(scene.data, [camera])[camera])
            except Exception as error:
                there.append(error)

        thread = threading.Thread(target=render_elsewhere)
        thread.start()
        thread.join(30)
        again = scene.sensors.render(scene.data, [camera])[camera]
    finally:
        scene.close()
    assert len(there) == 1 and not isinstance(there[0], Exception), there
    assert (there[0] == here).all() and (again == here).all()  # type: ignore[union-attr]


ENDED_DISPLAY = """
import mujoco
from mujoco import egl
from openral_sim.gl_guard import close_renderer, open_renderer

model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='1'/></worldbody></mujoco>")
kept = open_renderer(model, 32, 32)  # left to the exit hook
closed = open_renderer(model, 32, 32)
egl.EGL.eglTerminate(egl.EGL_DISPLAY)  # what robosuite's exit hook does, before ours
close_renderer(closed)
print("closed")
"""


def test_renderers_close_quietly_after_another_library_ended_the_display() -> None:
    """robosuite ends the process's EGL display in an exit hook of its own; a renderer of
    ours closed after it (by us, the exit hook or the collector) says nothing: before, each
    printed an EGL_NOT_INITIALIZED traceback at the end of a test run."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "MUJOCO_GL": "egl"}
    done = subprocess.run(
        [sys.executable, "-c", ENDED_DISPLAY], capture_output=True, text=True, env=env, timeout=60
    )
    assert done.returncode == 0 and done.stdout.strip() == "closed", done.stderr
    assert done.stderr == ""
