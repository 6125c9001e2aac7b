"""Tests for commands/deploy.py: ``openral deploy sim`` as a real subprocess."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from sensor_msgs.msg import Image, JointState

from benchmarks.real_time import manifest_with_rates
from tests.ros.ros_helpers import CAMERAS, FRANKA_SCENE, Probe, image_topic

OPENRAL = Path(sys.executable).parent / "openral"
EXIT_WAIT_S = 60.0
ENV = {**os.environ, "MUJOCO_GL": "egl", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


def deploy(*args: str, domain: int) -> subprocess.Popen[str]:
    command = [str(OPENRAL), "deploy", "sim", "--no-viewer", "--domain-id", str(domain), *args]
    return subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV
    )


@pytest.fixture
def remote_probe() -> Iterator[tuple[int, Probe]]:
    """A probe on a domain of its own, for a deploy process started on that domain."""
    domain = claim_domain_id()
    topics = {"/joint_states": JointState, **{image_topic(c): Image for c in CAMERAS}}
    with ros_session(domain_id=domain) as context, Spinner(context) as spinner:
        probe = Probe(context, topics, name="cli_probe")
        spinner.add_node(probe.node)
        yield domain, probe
        spinner.stop()
        probe.node.destroy_node()


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_deploy_sim_serves_the_graph_until_signalled_then_exits_0(
    remote_probe: tuple[int, Probe], stop: signal.Signals
) -> None:
    domain, probe = remote_probe
    process = deploy("--config", str(FRANKA_SCENE), domain=domain)
    try:
        for topic in ["/joint_states", *map(image_topic, CAMERAS)]:
            probe.wait_count(topic, 1, timeout_s=30.0)
        process.send_signal(stop)
        out, err = process.communicate(timeout=EXIT_WAIT_S)
    finally:
        process.kill()
    assert process.returncode == 0, err
    assert "/openral/cameras/agentview/image" in out and "/openral/safe_action" in out
    assert "stopped (signal)" in out and "clean shutdown" in out
    assert "Traceback" not in err


def test_deploy_sim_with_duration_exits_0_by_itself() -> None:
    process = deploy("--config", str(FRANKA_SCENE), "--duration", "2", domain=claim_domain_id())
    out, err = process.communicate(timeout=EXIT_WAIT_S)
    assert process.returncode == 0, err
    assert "stopped (--duration)" in out


def test_a_missing_scene_exits_1_with_one_line(tmp_path: Path) -> None:
    missing = tmp_path / "nope.yaml"
    process = deploy("--config", str(missing), domain=claim_domain_id())
    _, err = process.communicate(timeout=EXIT_WAIT_S)
    assert process.returncode == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "no such scene file" in lines[0] and str(missing) in lines[0]


def test_a_scene_that_fails_at_configure_exits_1_with_one_line(tmp_path: Path) -> None:
    scene = tmp_path / "bad_camera.yaml"
    text = FRANKA_SCENE.read_text()
    assert text.count("cameras: [agentview, wrist,") == 1
    scene.write_text(text.replace("cameras: [agentview, wrist,", "cameras: [agentview, nosuch,"))
    process = deploy("--config", str(scene), domain=claim_domain_id())
    _, err = process.communicate(timeout=EXIT_WAIT_S)
    assert process.returncode == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: configure failed:")
    assert "'nosuch' is not a camera sensor" in lines[0] and "agentview, wrist" in lines[0]


def test_each_camera_runs_at_its_manifest_rate_unless_camera_rate_overrides(
    tmp_path: Path,
) -> None:
    """--manifest runs a manifest outside robots/ (here the Panda's, cameras at 15 and 5 Hz);
    the printed interfaces show each sensor's own rate, and --camera-rate replaces them all."""
    manifest = manifest_with_rates(tmp_path, {"agentview": 15.0, "wrist": 5.0})
    for extra, rates in (([], ("15 Hz", "5 Hz")), (["--camera-rate", "7"], ("7 Hz", "7 Hz"))):
        process = deploy(
            "--config", str(FRANKA_SCENE), "--manifest", str(manifest), "--duration", "1",
            *extra, domain=claim_domain_id(),
        )  # fmt: skip
        out, err = process.communicate(timeout=EXIT_WAIT_S)
        assert process.returncode == 0, err
        rows = {line.split()[0]: line for line in out.splitlines() if "cameras/" in line}
        assert rates[0] in rows["/openral/cameras/agentview/image"], out
        assert rates[1] in rows["/openral/cameras/wrist/image"], out
