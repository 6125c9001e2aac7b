"""``openral rskill run`` against a fake deploy-sim graph: exit codes and what it publishes."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

import numpy as np
from openral_cli.main import app
from typer.testing import CliRunner

from tests.ros_runner.conftest import DOMAIN_ID, HOLD, RosHarness, wait_until

RUN = [sys.executable, "-m", "openral_cli.main", "rskill", "run", "--robot", "franka_panda"]
ENV = {**os.environ, "ROS_DOMAIN_ID": str(DOMAIN_ID), "COLUMNS": "300"}
SUMMARY = re.compile(r"wave on franka_panda: (\d+) action\(s\) on /openral/safe_action")


def test_run_for_a_duration_publishes_waves_and_exits_0(ros: RosHarness) -> None:
    graph = ros.fake_graph()
    result = CliRunner().invoke(
        app,
        ["rskill", "run", "--robot", "franka_panda", "--duration", "6", "-p", "amplitude=0.2"],
        env={"COLUMNS": "300", "ROS_DOMAIN_ID": str(DOMAIN_ID)},
    )
    assert result.exit_code == 0, result.output
    match = SUMMARY.search(result.output)
    assert match and int(match[1]) >= 1, result.output
    assert "(camera1 <- agentview, camera2 <- wrist)" in result.output
    assert wait_until(lambda: len(graph.received()) >= 1)
    offsets = np.array(graph.received()) - HOLD
    assert np.all(np.abs(offsets) <= 0.2 + 1e-9)


def test_ctrl_c_stops_the_runner_cleanly_with_exit_0(ros: RosHarness) -> None:
    graph = ros.fake_graph()
    process = subprocess.Popen(RUN, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV)
    try:
        assert wait_until(lambda: len(graph.received()) >= 5, timeout_s=30.0)
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 0, stderr.decode()
    match = SUMMARY.search(stdout.decode())
    assert match and int(match[1]) >= 5, stdout.decode()
    assert b"Traceback" not in stderr


def test_a_silent_camera_aborts_with_exit_1_and_one_message(ros: RosHarness) -> None:
    graph = ros.fake_graph(cameras=("agentview",))
    result = subprocess.run(
        [*RUN, "--frame-timeout", "6"], capture_output=True, text=True, timeout=60, env=ENV
    )
    assert result.returncode == 1, result.stdout
    message = " ".join(result.stderr.split())
    assert message.startswith(
        "error: policy wave needs camera slots (camera1, camera2) but got frames within 6 s "
        "only for (camera1); franka_panda: camera1 <- /openral/cameras/agentview/image, "
        "camera2 <- /openral/cameras/wrist/image"
    ), result.stderr
    assert "Traceback" not in result.stderr
    assert graph.received() == []
