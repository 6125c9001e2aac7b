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
TOPICS = {
    "/openral/manifest_joint_states": JointState,
    "/openral/safe_action": Float64MultiArray,
    "/openral/action_spec": JointState,
}
SWAYING = (0, 2, 3)
"""The joints the policy moves (shoulder_pan, elbow_flex, wrist_flex)."""
SECONDS = 10.0
PERIOD_S = 4.0
"""The sway's period [s] (SwayConfig's): the runs compare over at least one."""


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
            hold = np.array(remote.probe.latest("/openral/action_spec").position)
        finally:
            _, graph_err = stop(process)
    return (*_relative(actions, states, hold), graph_err)


def _relative(
    actions: list[Received], states: list[Received], hold: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Times from the first action seen and positions from the hold the policy sways
    around, of the joint states while actions came (after the last, the joints hold)."""
    start = actions[0].at
    states = [s for s in states if start <= s.at <= actions[-1].at]
    times = np.array([s.at - start for s in states])
    return times, np.array([list(s.msg.position) for s in states]) - hold


def _aligned(sim: tuple[np.ndarray, np.ndarray], real: tuple[np.ndarray, np.ndarray]) -> float:
    """The time [s] to add to the real run's so it lines up with the simulated one best (the
    probe may see the first actions of each run late: discovery takes its time)."""
    grid = np.arange(1.0, 5.0, 0.02)
    reference = np.interp(grid, sim[0], sim[1][:, 0])
    lags = np.arange(-1.5, 1.5, 0.01)
    errors = [
        np.abs(np.interp(grid - lag, real[0], real[1][:, 0]) - reference).max() for lag in lags
    ]
    return float(lags[int(np.argmin(errors))])


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
    lag = _aligned(sim[:2], real[:2])
    end = min(sim[0][-1], real[0][-1] + lag)  # each runner acted for its duration less its wait
    assert end > PERIOD_S, f"too short a common run: {end:.1f} s"
    grid = np.arange(max(0.5, lag + 0.5), end, 0.05)
    worst, where = 0.0, ""
    for joint in SWAYING:
        simulated = np.interp(grid, sim[0], sim[1][:, joint])
        measured = np.interp(grid - lag, real[0], real[1][:, joint])
        assert np.ptp(measured) > 0.25, f"joint {joint} hardly moved: {real[2]}"
        gap = np.abs(simulated - measured)
        if gap.max() > worst:
            at = int(gap.argmax())
            worst = float(gap.max())
            where = (
                f"joint {joint} at {grid[at]:.2f} s: sim {np.round(simulated[at - 4 : at + 4], 3)}"
                f" real {np.round(measured[at - 4 : at + 4], 3)}"
            )
    print(f"sim and real differ by up to {worst:.4f} rad")
    assert worst <= 0.05, f"sim and real differ by {worst:.3f} rad, {where}: {sim[2]} {real[2]}"
