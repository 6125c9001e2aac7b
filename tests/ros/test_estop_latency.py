"""Tests for manifest_node.py and sim_sensor_bridge.py: the E-stop answers quickly even when
one scene step is long. At ``control_freq_hz: 1`` every idle step simulates a whole second
of physics on the node's single executor thread, which the E-stop request has to wait for."""

from __future__ import annotations

import random
import statistics
import time
from pathlib import Path

import pytest
from openral_nodes.runtime import claim_domain_id
from sensor_msgs.msg import JointState

from tests.ros.lifecycle_client import DEPLOY_NODE, deploy_output, deploy_sim, outside_client
from tests.ros.ros_helpers import FRANKA_SCENE, Probe

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone

CALLS = 20
"""E-stop round trips measured."""
MEDIAN_LIMIT_S = 0.1
"""Longest accepted median round trip of ``/openral/estop`` [s]."""
IDLE_PERIOD_S = 0.1
"""Period of the idle stepper at deploy sim's default ``--camera-rate`` of 10 Hz [s]."""
START_WAIT_S = 90.0
"""Longest wait for deploy sim to load its scene and publish on a loaded machine [s]."""


def slow_scene(tmp_path: Path) -> Path:
    """A copy of the franka default scene whose control period is one second."""
    text = FRANKA_SCENE.read_text()
    assert text.count("control_freq_hz: 20.0") == 1 and "robot_id: franka_panda" in text
    scene = tmp_path / "tabletop_1hz.yaml"
    scene.write_text(text.replace("control_freq_hz: 20.0", "control_freq_hz: 1.0"))
    return scene


def test_estop_answers_within_100_ms_while_each_scene_step_is_a_second_of_physics(
    tmp_path: Path,
) -> None:
    domain = claim_domain_id()
    with (
        deploy_sim(slow_scene(tmp_path), domain, tmp_path) as process,
        outside_client(domain, DEPLOY_NODE, "estop_peer") as client,
    ):
        probe = Probe(client.node.context, {"/joint_states": JointState}, name="estop_probe")
        client.spinner.add_node(probe.node)
        probe.wait_count("/joint_states", 1, timeout_s=START_WAIT_S)
        client.trigger("/openral/release_estop")  # discovery and a first call, not measured
        round_trips, phases = [], random.Random(0)
        for _ in range(CALLS):
            # Call at a random phase of the 10 Hz idle stepper: a joint state arrives right
            # after each step (its timer waited for the step), so add a random 0-100 ms.
            probe.wait_count("/joint_states", 1, start=time.monotonic())
            time.sleep(phases.uniform(0.0, IDLE_PERIOD_S))
            response, round_trip = client.trigger("/openral/estop")
            assert response.success, response.message
            round_trips.append(round_trip)
            assert client.trigger("/openral/release_estop")[0].success
        client.spinner.remove_node(probe.node)
        probe.node.destroy_node()
        assert process.poll() is None, deploy_output(tmp_path)[1]
    median, worst = statistics.median(round_trips), max(round_trips)
    print(f"/openral/estop round trip over {CALLS} calls: median {median * 1e3:.1f} ms, ", end="")
    print(f"max {worst * 1e3:.1f} ms")
    assert median < MEDIAN_LIMIT_S, f"median {median * 1e3:.1f} ms, max {worst * 1e3:.1f} ms"
