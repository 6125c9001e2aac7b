"""``openral rskill run`` names only the cameras the graph renders, not every manifest slot."""

from __future__ import annotations

import re

from openral_cli.main import app
from typer.testing import CliRunner

from tests.ros_runner.conftest import DOMAIN_ID, RosHarness

ENV = {"COLUMNS": "300", "ROS_DOMAIN_ID": str(DOMAIN_ID)}
ROUTES = re.compile(r"action\(s\) on /openral/safe_action in [\d.]+ s \((.*)\)")


def _routes(*args: str) -> str:
    result = CliRunner().invoke(
        app, ["rskill", "run", "--robot", "franka_panda", "--duration", "4", *args], env=ENV
    )
    assert result.exit_code == 0, result.output
    match = ROUTES.search(result.output)
    assert match, result.output
    return match[1]


def test_a_camera_the_scene_does_not_render_is_not_listed(ros: RosHarness) -> None:
    ros.fake_graph(cameras=("agentview",))  # franka's manifest also has wrist (camera2)
    assert _routes("-p", "required_slots=camera1") == "camera1 <- agentview"


def test_no_rendered_camera_reads_no_cameras(ros: RosHarness) -> None:
    ros.fake_graph(cameras=())
    assert _routes("-p", "required_slots=") == "no cameras"
