"""The same one-file policy against deploy sim and against deploy real (through the bus
emulator, not hardware): the joints follow the same path within 0.05 rad (the servos' own
dynamics differ from the simulated actuators')."""

from __future__ import annotations

import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from openral_core.paths import repo_root
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from tests.real.deploy_helpers import RemoteBus, deploy_real, openral, remote_graph, stop
from tests.ros.ros_helpers import Received

pytestmark = pytest.mark.exclusive  # two live graphs, one after the other, in real time

POLICY = '''\
"""Three joints sway around the pose the robot holds."""

import math

import numpy as np
from pydantic import BaseModel


class SwayConfig(BaseModel):
    amplitude: float = 0.3  # rad
    period_s: float = 4.0


class Sway:
    config_type = SwayConfig
    required_slots = ()
    needs_privileged = False

    def __init__(self, config: SwayConfig) -> None:
        self.config = config

    def act(self, obs):
        names, hold = obs["action_spec"]
        action = np.array(hold, dtype=np.float64)
        swing = self.config.amplitude * math.sin(2 * math.pi * obs["time_s"] / self.config.period_s)
        action[0] += swing
        action[2] += swing
        action[3] -= swing / 2
        return action
'''
TOPICS = {"/openral/manifest_joint_states": JointState, "/openral/safe_action": Float64MultiArray}
SWAYING = (0, 2, 3)
"""The joints the policy moves (shoulder_pan, elbow_flex, wrist_flex)."""
SECONDS = 9.0


def _run(
    policy: Path, start_graph: Callable[[int], subprocess.Popen[str]]
) -> tuple[np.ndarray, np.ndarray, str]:
    """Start a graph, run the policy against it; (times [s] from the first action,
    positions relative to where the joints were then) of every joint state, and what the
    graph printed on stderr."""
    with remote_graph(TOPICS) as remote:
        process = start_graph(remote.domain)
        try:
            remote.probe.wait_count("/openral/manifest_joint_states", 1, timeout_s=60.0)
            runner = openral(
                "rskill", "run", "--robot", "so101", "--policy", f"{policy}:Sway",
                "--duration", str(SECONDS), "--domain-id", str(remote.domain),
            )  # fmt: skip
            _, err = runner.communicate(timeout=120)
            assert runner.returncode == 0, err
            actions = remote.probe.since("/openral/safe_action", 0.0)
            states = remote.probe.since("/openral/manifest_joint_states", 0.0)
        finally:
            _, graph_err = stop(process)
    return (*_relative(actions, states), graph_err)


def _relative(actions: list[Received], states: list[Received]) -> tuple[np.ndarray, np.ndarray]:
    start = actions[0].at
    times = np.array([s.at - start for s in states])
    positions = np.array([list(s.msg.position) for s in states])
    at_start = positions[np.searchsorted(times, 0.0)]
    return times, positions - at_start


def test_one_policy_moves_sim_and_real_alike(tmp_path: Path) -> None:
    policy = tmp_path / "sway.py"
    policy.write_text(POLICY)
    scene = repo_root() / "robots" / "so101" / "scenes" / "tabletop.yaml"
    sim = _run(
        policy,
        lambda domain: openral(
            "deploy", "sim", "--config", str(scene), "--no-viewer", "--domain-id", str(domain)
        ),
    )
    bus = RemoteBus(tmp_path)
    try:
        real = _run(policy, lambda domain: deploy_real(bus.path, bus.calibration, domain))
    finally:
        bus.close()
    end = min(sim[0][-1], real[0][-1]) - 0.2  # each runner acted for its duration less its wait
    assert end > 5.0, f"too short a common run: {end:.1f} s"
    grid = np.arange(0.5, end, 0.05)
    worst = 0.0
    for joint in SWAYING:
        simulated = np.interp(grid, sim[0], sim[1][:, joint])
        measured = np.interp(grid, real[0], real[1][:, joint])
        assert np.ptp(measured) > 0.25, f"joint {joint} hardly moved: {real[2]}"
        worst = max(worst, float(np.abs(simulated - measured).max()))
    print(f"sim and real differ by up to {worst:.4f} rad")
    assert worst <= 0.05, f"sim and real differ by up to {worst:.3f} rad: {sim[2]} {real[2]}"
