"""Every command that needs ROS 2 says which extra to install when rclpy is missing."""

from __future__ import annotations

import sys

import pytest
from openral_cli.main import app
from openral_core.errors import OpenralError
from typer.testing import CliRunner

from tests.conftest import ROBOTS

SCENE = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")


@pytest.mark.parametrize(
    "args",
    [
        ["deploy", "sim", "--config", SCENE, "--no-viewer"],
        ["ros", "topics"],
        ["ros", "services"],
        ["ros", "actions"],
        ["ros", "nodes", "--all"],
        ["ros", "echo", "/joint_states", "--once"],
        ["ros", "snapshot", "/openral/cameras/agentview/image", "--out", "x.png"],
        ["rskill", "run", "--robot", "franka_panda"],
    ],
)
def test_a_missing_ros_install_is_one_clear_error(
    monkeypatch: pytest.MonkeyPatch, args: list[str]
) -> None:
    monkeypatch.setitem(sys.modules, "rclpy", None)  # `import rclpy` now raises ImportError
    result = CliRunner().invoke(app, args)
    assert isinstance(result.exception, OpenralError), result.output
    assert "install the 'ros' extra (pip install 'openral[ros]')" in str(result.exception)
