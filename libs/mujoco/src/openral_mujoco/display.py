"""Is there a screen? And the one place that chooses the GL backend MuJoCo renders with.

Imports nothing heavy: it must run before the first ``import mujoco``, which reads
``MUJOCO_GL`` once.
"""

from __future__ import annotations

import os

OFFSCREEN_GL = "egl"
"""MuJoCo's GL backend without a screen (Mesa's llvmpipe on the CPU)."""


def has_display() -> bool:
    """True when an X11 or Wayland display is available."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def render_offscreen_when_headless() -> None:
    """Without a display, make MuJoCo render with EGL (unless ``MUJOCO_GL`` is already set)."""
    if not has_display():
        os.environ.setdefault("MUJOCO_GL", OFFSCREEN_GL)


def use_offscreen_gl() -> None:
    """Render offscreen with EGL even with a display (unless ``MUJOCO_GL`` is already set):
    for code that never opens a window (robosuite's renderer, the docs pictures)."""
    os.environ.setdefault("MUJOCO_GL", OFFSCREEN_GL)
