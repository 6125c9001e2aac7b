"""One OpenGL operation at a time in a process.

``deploy sim`` renders on up to three threads at once (the RGB cameras' render thread, one
per depth camera, and the caller's own renders), each with its own EGL context, as
MuJoCo's documentation allows. A fresh-clone CI run nevertheless crashed once
(segmentation fault) inside ``mjr_render`` on a depth thread while other contexts of the
same process were live; it did not recur in a 60 s stress of three rendering threads plus
renderers made and freed on a fourth, so the race is rare and sits below our code (Mesa's
software rasterizer, llvmpipe, is the suspect). Every MuJoCo render, renderer creation and
free in :mod:`openral_sim` therefore holds :data:`GL_LOCK`.

Cost: llvmpipe already spreads one render over every core, so two renders at once only
share the cores two ways; serialized, a frame waits at most for one other frame, which the
frame renderers' retry (:mod:`openral_bridge.frame_renderer`) absorbs. Checked by the
real-time camera-rate tests (each camera within 10 % of its rate with the lock, on a
fresh clone); the camera benchmarks were not re-run with it.
"""

from __future__ import annotations

import threading

import mujoco

__all__ = ["GL_LOCK", "close_renderer", "open_renderer"]

GL_LOCK = threading.Lock()
"""Held around every OpenGL call this package makes (never while waiting on anything
else, so it cannot deadlock with the HAL's lock)."""


def open_renderer(model: mujoco.MjModel, height: int, width: int) -> mujoco.Renderer:
    """A ``mujoco.Renderer`` of ``model`` at ``height`` x ``width`` [px], made holding
    :data:`GL_LOCK` (its context belongs to the calling thread)."""
    with GL_LOCK:
        return mujoco.Renderer(model, height, width)


def close_renderer(renderer: mujoco.Renderer) -> None:
    """Free ``renderer``'s context holding :data:`GL_LOCK` (idempotent)."""
    with GL_LOCK:
        renderer.close()
