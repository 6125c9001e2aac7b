"""The browser view of a ``sim run``, photographed in headless Chromium.

``python -m tests.docs.view_screenshot OUT.png`` (from the repository root; ``just
docs-view-image`` writes the guide's picture with it) runs ``openral sim run --view`` on the
franka tabletop, opens the page in headless Chromium and saves the first screenshot that
:func:`looks_drawn` accepts; the docs test asserts the same of its own screenshot.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from tests.docs.headless_chromium import free_port, open_page

REPO = Path(__file__).resolve().parents[2]
SCENE = "robots/franka_panda/scenes/tabletop.yaml"
DRAW_WAIT_S = 150.0
"""How long the page may take to load Rerun's Wasm viewer and draw (software GL)."""


@dataclass(frozen=True)
class Looks:
    """Fractions of pixels of a screenshot's regions with the scene's colours."""

    arm_dark: float
    """The Panda's black links, in the 3-D panel (left 60 %)."""
    table: float
    """The brown table, in the 3-D panel."""
    floor: float
    """The grey-blue floor, in the 3-D panel."""
    camera: float
    """The table seen by the first camera panel (top right)."""

    def drawn(self) -> bool:
        """Geometry, posed bodies and a camera frame are all on screen."""
        return (
            self.arm_dark > 0.001 and self.table > 0.01 and self.floor > 0.05 and self.camera > 0.01
        )


def looks(png: Path) -> Looks:
    """Measure a screenshot of the view (layout of :mod:`openral_sim.browser_view`)."""
    pixels = np.asarray(Image.open(png).convert("RGB")).astype(int)
    height, width, _ = pixels.shape
    scene = pixels[50 : height - 40, : int(0.6 * width)]
    camera = pixels[60 : int(0.27 * height), int(0.62 * width) :]
    return Looks(
        arm_dark=float((scene < 70).all(-1).mean()),
        table=_brown(scene),
        floor=float((np.abs(scene - [138, 150, 160]) < 20).all(-1).mean()),
        camera=_brown(camera),
    )


def _brown(region: np.ndarray) -> float:
    r, g, b = region[..., 0], region[..., 1], region[..., 2]
    return float(((r > g + 15) & (g > b + 15) & (r > 120)).mean())


def serve(*args: str) -> tuple[subprocess.Popen[str], str]:
    """``openral ARGS`` (a command that serves a view) and what it printed up to the line
    saying it serves the view."""
    command = [sys.executable, "-m", "openral_cli.main", *args]
    env = {**os.environ, "COLUMNS": "200", "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    process = subprocess.Popen(
        command, cwd=REPO, env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    assert process.stdout is not None
    printed = []
    for line in process.stdout:
        printed.append(line)
        if line.startswith("serving the view"):
            return process, "".join(printed)
    raise AssertionError(f"openral {' '.join(args)} ended early: {process.communicate()[1]}")


def start_view(port: int) -> subprocess.Popen[str]:
    """``openral sim run --view`` on :data:`SCENE`, once it says the view is served."""
    return serve(
        "sim", "run", "--config", SCENE, "--steps", "40", "--view", "--view-port", str(port)
    )[0]


def view_url(port: int) -> str:
    """The page of a view on ``port`` (its data stream on the next port)."""
    return f"http://127.0.0.1:{port}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{port + 1}%2Fproxy"


def free_port_pair() -> int:
    """A port whose next port is free too (the page and the data stream)."""
    for _ in range(50):
        port = free_port()
        if port < 65534 and _free(port + 1):
            return port
    raise AssertionError("no two free consecutive ports")


def _free(port: int) -> bool:
    import socket

    with socket.socket() as probe:
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def photograph(url: str, out: Path, done: Callable[[Path], bool] | None = None) -> Looks:
    """Screenshots of ``url`` every 3 s until one is drawn (``done``, else
    :meth:`Looks.drawn`) or :data:`DRAW_WAIT_S` passed; the last is at ``out``."""
    deadline = time.monotonic() + DRAW_WAIT_S
    with open_page(url) as page:
        while True:
            time.sleep(3.0)
            page.screenshot(out)
            seen = looks(out)
            finished = done(out) if done is not None else seen.drawn()
            if finished or time.monotonic() > deadline:
                return seen


def stop(process: subprocess.Popen[str]) -> tuple[int, str]:
    """Ctrl-C the run; its exit code and standard error."""
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=30)
    return process.returncode, err


def main(out: Path) -> None:
    """Write a drawn screenshot of the view to ``out``."""
    port = free_port_pair()
    process = start_view(port)
    try:
        seen = photograph(view_url(port), out)
    finally:
        stop(process)
    print(f"{out}: {seen}")
    if not seen.drawn():
        raise SystemExit(1)


if __name__ == "__main__":
    main(Path(sys.argv[1]))
