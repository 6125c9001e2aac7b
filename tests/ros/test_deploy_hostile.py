"""Tests for deploy.py and manifest_node.py against hostile peers: ``openral deploy sim`` as a
subprocess takes every invalid transition id in every state it can be walked to, keeps its
E-stop and ``/joint_states`` rate, and ends with exit 0 on a shutdown requested over ROS."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from lifecycle_msgs.msg import Transition
from openral_nodes.runtime import claim_domain_id
from sensor_msgs.msg import JointState

from tests.ros.lifecycle_client import (
    DEPLOY_ENV,
    DEPLOY_NODE,
    LABELS,
    OPENRAL,
    VALID,
    LifecycleClient,
    deploy_output,
    deploy_sim,
    outside_client,
)
from tests.ros.ros_helpers import FRANKA_SCENE, Probe

T = Transition
START_WAIT_S = 90.0
"""Longest wait for deploy sim to load its scene and publish on a loaded machine [s]."""
EXIT_WAIT_S = 15.0
"""Longest wait for the process to end after a shutdown transition [s]."""
JOINT_STATE_HZ = 50.0
"""deploy sim's default ``--joint-state-rate`` [Hz]."""
RATE_SAMPLES = 100
"""Messages the rate is measured over (about 2 s at 50 Hz)."""
BAD_LABELS = ("bogus", "configure", "ACTIVATE", "x" * 500)


@dataclass(frozen=True)
class Live:
    """A running deploy sim process, an outside lifecycle client and a probe."""

    process: subprocess.Popen[str]
    client: LifecycleClient
    probe: Probe
    logs: Path


@pytest.fixture
def live(tmp_path: Path) -> Iterator[Live]:
    """deploy sim on the franka scene, active and publishing, with a client and a probe."""
    domain = claim_domain_id()
    with (
        deploy_sim(FRANKA_SCENE, domain, tmp_path) as process,
        outside_client(domain, DEPLOY_NODE, "hostile_peer") as client,
    ):
        probe = Probe(client.node.context, {"/joint_states": JointState}, name="hostile_probe")
        client.spinner.add_node(probe.node)
        try:
            probe.wait_count("/joint_states", 1, timeout_s=START_WAIT_S)
            client.wait_ready()
            assert client.state() == "active"
            yield Live(process, client, probe, tmp_path)
        finally:
            client.spinner.remove_node(probe.node)
            probe.node.destroy_node()


def refuse_everything_invalid(client: LifecycleClient, state: str) -> None:
    """Every transition id (0-255) and some labels the state does not allow: all refused."""
    for transition_id in range(256):
        if transition_id not in VALID[state]:
            assert client.change(transition_id) is False, f"id {transition_id} in {state}"
    valid_id = next(iter(VALID[state]))  # the label wins: the request is still refused
    for label in BAD_LABELS:
        if label not in LABELS[state]:
            assert client.change(valid_id, label=label) is False, f"{label!r} in {state}"
    assert client.state() == state


def joint_state_rate_hz(probe: Probe) -> float:
    """Rate of ``/joint_states`` over :data:`RATE_SAMPLES` messages arriving from now [Hz]."""
    start = time.monotonic()
    got = probe.wait_count("/joint_states", RATE_SAMPLES, start=start, timeout_s=30.0)
    return (len(got) - 1) / (got[-1].at - got[0].at)


def test_invalid_transitions_in_every_state_leave_the_graph_serving(live: Live) -> None:
    client, probe = live.client, live.probe
    baseline = joint_state_rate_hz(probe)  # this machine, this run, before any hostile call
    refuse_everything_invalid(client, "active")
    client.walk(T.TRANSITION_DEACTIVATE)
    refuse_everything_invalid(client, "inactive")
    client.walk(T.TRANSITION_CLEANUP)
    refuse_everything_invalid(client, "unconfigured")
    client.walk(T.TRANSITION_CONFIGURE, T.TRANSITION_ACTIVATE)
    refuse_everything_invalid(client, "active")

    estop, _ = client.trigger("/openral/estop")
    assert estop.success, estop.message
    release, _ = client.trigger("/openral/release_estop")
    assert release.success, release.message
    rate = joint_state_rate_hz(probe)
    # On two loaded cores the camera renders share the executor and hold the rate near
    # 40-50 Hz of the configured 50; compared with the rate measured before in this run,
    # a graph the requests had stalled or slowed fails, machine load does not.
    shown = f"/joint_states at {rate:.1f} Hz after, {baseline:.1f} Hz before"
    assert rate >= 0.8 * baseline, shown
    assert baseline >= 0.5 * JOINT_STATE_HZ, shown
    print(shown)

    assert live.process.poll() is None, "deploy sim ended"
    _, err = deploy_output(live.logs)
    assert "change_state refused: transition id 0 is not valid in state active" in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    "walk",
    [(), (T.TRANSITION_DEACTIVATE,), (T.TRANSITION_DEACTIVATE, T.TRANSITION_CLEANUP)],
    ids=["from-active", "from-inactive", "from-unconfigured"],
)
def test_a_shutdown_over_ros_ends_deploy_sim_with_exit_0(live: Live, walk: tuple[int, ...]) -> None:
    live.client.walk(*walk)
    asked = time.monotonic()
    assert live.client.change(0, label="shutdown") is True
    returncode = live.process.wait(EXIT_WAIT_S)
    print(f"deploy sim ended {time.monotonic() - asked:.2f} s after the shutdown request")
    out, err = deploy_output(live.logs)
    assert returncode == 0, err
    assert "stopped (shutdown transition requested over ROS)" in out, out
    assert "clean shutdown" in out
    assert "Traceback" not in err, err


@pytest.mark.parametrize("option", ["--camera-rate", "--joint-state-rate"])
def test_a_rate_over_1000_hz_is_refused_on_the_command_line(option: str) -> None:
    command = [str(OPENRAL), "deploy", "sim", "--config", str(FRANKA_SCENE), option, "1001"]
    done = subprocess.run(command, capture_output=True, text=True, env=DEPLOY_ENV, timeout=60)
    assert done.returncode == 2, done.stderr
    assert option in done.stderr and "1000" in done.stderr
