"""What the CLI keeps out of a command's start-up: rich until something is printed, and the
ROS message code generator always (``deploy sim`` reaches its first message sooner)."""

from __future__ import annotations

import subprocess
import sys

import pytest
from openral_cli.ros_available import CODE_GENERATOR, require_ros


def test_starting_the_cli_imports_no_rich() -> None:
    code = "import sys, openral_cli.main; print(sorted(m for m in sys.modules if 'rich' in m))"
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "[]"


def test_require_ros_keeps_the_message_code_generator_out(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("rclpy")
    monkeypatch.delitem(sys.modules, CODE_GENERATOR, raising=False)
    try:
        require_ros()
        assert sys.modules[CODE_GENERATOR] is None
        from sensor_msgs.msg import JointState  # type support still loads

        assert JointState(name=["a"]).name == ["a"]
    finally:
        sys.modules.pop(CODE_GENERATOR, None)
