"""`./bootstrap demo` is the demo's own process: a signal to its PID stops the graph at once.

The README's main job is started exactly as printed; SIGINT or SIGTERM goes to that one
PID (not its process group, as ``kill <pid>`` from another shell would), and the demo must
exit 0 within 2 s.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from tests.conftest import REPO

READY = "running; stop with Ctrl-C"
READY_TIMEOUT_S = 120.0
STOP_LIMIT_S = 2.0


@pytest.fixture(scope="module")
def ros_domain() -> str:
    from openral_nodes.runtime import claim_domain_id

    return str(claim_domain_id())


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
def test_a_signal_to_the_demo_pid_stops_it_cleanly(
    sig: signal.Signals, ros_domain: str, tmp_path: Path
) -> None:
    log = tmp_path / "demo.log"
    env = {**os.environ, "ROS_DOMAIN_ID": ros_domain}
    with log.open("wb") as sink:
        demo = subprocess.Popen(
            ["./bootstrap", "demo"],
            cwd=REPO,
            env=env,
            stdout=sink,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:
        deadline = time.monotonic() + READY_TIMEOUT_S
        while READY not in log.read_text("utf-8", errors="replace"):
            assert demo.poll() is None, log.read_text("utf-8", errors="replace")
            assert time.monotonic() < deadline, "the demo never printed its running line"
            time.sleep(0.1)
        assert Path(f"/proc/{demo.pid}/exe").resolve().name.startswith("python"), (
            "the PID of ./bootstrap demo should be the openral process itself"
        )
        sent = time.monotonic()
        os.kill(demo.pid, sig)
        code = demo.wait(timeout=30)
        took = time.monotonic() - sent
    finally:
        if demo.poll() is None:
            os.killpg(demo.pid, signal.SIGKILL)
            demo.wait()
    output = log.read_text("utf-8", errors="replace")
    assert code == 0, output
    assert took <= STOP_LIMIT_S, f"stopped {took:.2f} s after {sig.name}"
    assert "clean shutdown" in output
