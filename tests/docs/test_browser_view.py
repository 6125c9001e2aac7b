"""The browser view (``--view``) from outside: Rerun's page in headless Chromium.

``openral sim run --view`` on the franka tabletop serves the page and the data stream on
127.0.0.1 only; Chromium loads it (Rerun's Wasm viewer, from the wheel, nothing fetched)
and within :data:`~tests.docs.view_screenshot.DRAW_WAIT_S` its screenshot shows the floor,
the table and the arm's links in the 3-D panel and the table in the first camera panel;
Ctrl-C then ends the command with exit 0. A port already taken is one line and exit 1.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

from tests.docs.headless_chromium import listening
from tests.docs.view_screenshot import (
    REPO,
    SCENE,
    free_port_pair,
    photograph,
    serve,
    start_view,
    stop,
    view_url,
)


def test_the_view_shows_the_arm_and_a_camera_in_headless_chromium(tmp_path: Path) -> None:
    port = free_port_pair()
    process = start_view(port)
    try:
        assert listening(port) == listening(port + 1) == ["127.0.0.1"], "loopback only"
        seen = photograph(view_url(port), tmp_path / "view.png")
        print(f"screenshot: {seen}")
        assert seen.drawn(), seen
    finally:
        code, err = stop(process)
    assert code == 0, err
    assert "Traceback" not in err


def test_a_taken_port_is_one_line_and_exit_1() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1] - 1  # the data stream's port is taken
        command = [sys.executable, "-m", "openral_cli.main", "sim", "run", "--config", SCENE,
                   "--steps", "2", "--view", "--view-port", str(port)]  # fmt: skip
        env = {**os.environ, "COLUMNS": "200"}
        done = subprocess.run(
            command, cwd=REPO, env=env, capture_output=True, text=True, timeout=120
        )
    assert done.returncode == 1
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "--view: the view cannot listen on 127.0.0.1:" in lines[0], (
        done.stderr
    )


def test_a_policy_episode_is_viewed_and_served_until_ctrl_c() -> None:
    port = free_port_pair()
    args = ("--policy", "scripted_lift", "--steps", "12", "--view", "--view-port", str(port))
    process, text = serve("sim", "run", "--config", SCENE, *args)
    try:
        assert f"view: {view_url(port)}" in text and "scripted_lift" in text, text
        assert listening(port) == listening(port + 1) == ["127.0.0.1"]
    finally:
        code, err = stop(process)
    assert code == 0 and "Traceback" not in err, err
