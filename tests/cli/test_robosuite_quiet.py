"""A robosuite scene runs without robosuite's import-time notices on the console."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.conftest import REPO


def test_sim_run_on_the_robosuite_scene_prints_only_its_own_lines(tmp_path: Path) -> None:
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "openral_cli.main",
            "sim",
            "run",
            "--config",
            str(REPO / "robots/franka_panda/scenes/lift_robosuite.yaml"),
            "--steps",
            "2",
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        env={**os.environ, "MUJOCO_GL": "egl"},
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    printed = result.stdout + result.stderr
    assert "[robosuite" not in printed, printed
    assert "robosuite" in result.stdout  # the run's own table names the backend
