"""One OpenGL operation at a time in a process.

``deploy sim`` renders on up to three threads at once (the RGB cameras' render thread, one
per depth camera, and the caller's own renders), each with its own EGL context, as
MuJoCo's documentation allows. A fresh-clone CI run nevertheless crashed once
(segmentation fault) inside ``mjr_render`` on a depth thread while other contexts of the
same process were live; it did not recur in a 60 s stress of three rendering threads plus
renderers made and freed on a fourth, so the race is rare and sits below our code (Mesa's
software rasterizer, llvmpipe, is the suspect). Every MuJoCo render, renderer creation and
free in :mod:`openral_sim` therefore holds :data:`GL_LOCK`.

A process forked from one that has opened a context cannot render: the driver's threads
(llvmpipe's) do not survive the fork, and its first context waits for them forever (seen:
gymnasium's ``AsyncVectorEnv`` with cameras on, whose default start method forks after its
first env was built in the parent). :func:`open_renderer` (and :func:`claim_gl`, which a
library's own renderer is announced with) refuses that in one line naming the way out, a
process started afresh (``forkserver`` or ``spawn``).

A context may be current on one thread only (EGL answers ``EGL_BAD_ACCESS`` otherwise),
and a scene's renderer is used by whichever thread steps it: a bus emulator built on the
main thread steps on its own, a camera capture developed on another. :func:`gl_turn` (the
lock plus a release of the calling thread's context on the way out) therefore leaves no
context current outside a render, so any thread may render with any renderer next.

Cost: llvmpipe already spreads one render over every core, so two renders at once only
share the cores two ways; serialized, a frame waits at most for one other frame, which the
frame renderers' retry (:mod:`openral_bridge.frame_renderer`) absorbs. Checked by the
real-time camera-rate tests (each camera within 10 % of its rate with the lock, on a
fresh clone); the camera benchmarks were not re-run with it.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import threading
import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import mujoco
from openral_mujoco.errors import HalError

__all__ = [
    "GL_LOCK",
    "InheritedGlError",
    "claim_gl",
    "close_renderer",
    "gl_turn",
    "open_renderer",
]

GL_LOCK = threading.Lock()
"""Held around every OpenGL call this package makes (never while waiting on anything
else, so it cannot deadlock with the HAL's lock)."""


_open: weakref.WeakSet[mujoco.Renderer] = weakref.WeakSet()
"""Renderers made by :func:`open_renderer` and not yet closed."""
_closes_at_exit = False
"""Whether :func:`_close_open_renderers` is registered to run at exit."""

_opened_in: int | None = None
"""The process that opened this module's first GL context (a forked child inherits it)."""


class InheritedGlError(HalError):
    """This process was forked from one that had opened OpenGL contexts; it cannot render."""


def claim_gl() -> None:
    """Record that this process opens OpenGL contexts now (a renderer of ours, or one a
    library such as robosuite makes itself).

    Raises:
        InheritedGlError: This process was forked after its parent had opened a context.
    """
    global _opened_in
    if _opened_in is not None and _opened_in != os.getpid():
        raise InheritedGlError(
            f"process {os.getpid()} was forked from process {_opened_in} after it had "
            "opened OpenGL contexts, and cannot render (the renderer would wait forever); "
            "start it afresh instead: multiprocessing's 'forkserver' or 'spawn' (gymnasium: "
            "AsyncVectorEnv(..., context='forkserver')), or render nothing (sensors=False)"
        )
    _opened_in = os.getpid()


@contextmanager
def gl_turn() -> Iterator[None]:
    """This thread's turn at OpenGL: holds :data:`GL_LOCK`, and on the way out makes no
    context current on this thread, so the next render may come from any thread."""
    with GL_LOCK:
        try:
            yield
        finally:
            _release_current()


def _release_current() -> None:
    """Make no context current on the calling thread (MuJoCo's offscreen back-ends; a
    GLFW window's context stays with its thread)."""
    backend = os.environ.get("MUJOCO_GL", "").lower()
    if backend == "egl":
        from mujoco import egl

        if egl.EGL_DISPLAY is not None:
            with _unless_display_ended():
                egl.EGL.eglMakeCurrent(
                    egl.EGL_DISPLAY,
                    egl.EGL.EGL_NO_SURFACE,
                    egl.EGL.EGL_NO_SURFACE,
                    egl.EGL.EGL_NO_CONTEXT,
                )
    elif backend == "osmesa":
        from OpenGL import GL, osmesa  # type: ignore[import-untyped]

        osmesa.OSMesaMakeCurrent(None, None, GL.GL_FLOAT, 0, 0)


def open_renderer(model: mujoco.MjModel, height: int, width: int) -> mujoco.Renderer:
    """A ``mujoco.Renderer`` of ``model`` at ``height`` x ``width`` [px], made in
    :func:`gl_turn` (no thread holds its context afterwards).

    Raises:
        InheritedGlError: This process was forked after its parent had opened a context.
    """
    global _closes_at_exit
    claim_gl()
    with gl_turn():
        renderer = mujoco.Renderer(model, height, width)
    _open.add(renderer)
    if not _closes_at_exit:  # after MuJoCo's own exit hook (the display's end): before it
        atexit.register(_close_open_renderers)
        _closes_at_exit = True
    return renderer


def close_renderer(renderer: mujoco.Renderer) -> None:
    """Free ``renderer``'s context holding :data:`GL_LOCK` (idempotent)."""
    with gl_turn(), _unless_display_ended(lambda: _forget(renderer)):
        renderer.close()
    _open.discard(renderer)


EGL_NOT_INITIALIZED = 0x3001
"""EGL's error for a display that was ended (``eglTerminate``)."""


@contextmanager
def _unless_display_ended(then: Callable[[], None] | None = None) -> Iterator[None]:
    """Let an EGL call fail quietly when the display was ended, and run ``then``: at exit,
    robosuite ends the process's one EGL display (its own exit hook, registered when it
    made its context: after ours if its scene came after a native one), and every context
    is gone with it. Any other failure is raised."""
    try:
        yield
    except Exception as error:
        if getattr(error, "err", None) != EGL_NOT_INITIALIZED:
            raise
        if then is not None:
            then()


def _forget(renderer: mujoco.Renderer) -> None:
    """Drop a renderer's contexts without freeing them (the display that held them was
    ended), so that neither it nor its context tries again when collected."""
    context = getattr(renderer, "_gl_context", None)
    if context is not None and hasattr(context, "_context"):
        context._context = None
    for attribute in ("_gl_context", "_mjr_context"):  # mujoco.Renderer's own (3.8)
        setattr(renderer, attribute, None)


def _close_open_renderers() -> None:
    """At exit, free every renderer still open while the EGL display still exists (MuJoCo
    ends the display in an exit hook of its own; a context freed after it raises)."""
    for renderer in list(_open):
        with contextlib.suppress(Exception):  # the process is ending: free what frees
            close_renderer(renderer)
