"""``openral sim run --policy``: one episode, exactly the one a sweep runs for that seed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from openral_eval.episode import EpisodeSpec, close_scenes, run_episode

from tests.conftest import ROBOTS

OPENRAL = Path(sys.executable).parent / "openral"
TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
WAVE = """
import math
import numpy as np

class Wave:
    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        names, hold = obs["action_spec"]
        action = np.array(hold, dtype=np.float64)
        action[0] += 0.2 * math.sin(obs["time_s"])
        return action
"""


def _sim_run(*args: str) -> subprocess.CompletedProcess[str]:
    command = [str(OPENRAL), "sim", "run", "--config", str(TABLETOP), *args]
    env = {**os.environ, "COLUMNS": "250"}  # a long file path stays on one table row
    return subprocess.run(command, capture_output=True, text=True, timeout=240, env=env)


def test_it_runs_the_sweeps_episode_for_the_seed(tmp_path: Path) -> None:
    result = _sim_run("--policy", "scripted_lift", "--seed", "3", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    line = json.loads((tmp_path / "episode.json").read_text())
    assert line["success"] is True and (tmp_path / "episode.mp4").stat().st_size > 0
    try:
        here = run_episode(EpisodeSpec(str(TABLETOP), 3, "scripted_lift", (), None))
    finally:
        close_scenes()
    assert line["trajectory_sha256"] == here.trajectory_sha256
    assert line["steps"] == here.steps


def test_a_policy_from_a_file_runs_for_the_steps_given(tmp_path: Path) -> None:
    (tmp_path / "wave.py").write_text(WAVE)
    result = _sim_run("--policy", f"{tmp_path / 'wave.py'}:Wave", "--steps", "7")
    assert result.returncode == 0, result.stderr
    row = next(line for line in result.stdout.splitlines() if ":Wave" in line)
    assert row.split("│")[3].strip() == "7"


def test_refusals_are_one_line() -> None:
    robot = _sim_run("--policy", "wave", "--robot", "ur5e")
    assert robot.returncode == 2 and "drop --robot/--manifest" in robot.stderr
    failing = _sim_run("--policy", "wave", "-p", "required_slots=camera9", "--steps", "2")
    assert failing.returncode == 1
    assert "the episode ended with an error: ValueError: policy WavePolicy needs camera" in (
        failing.stdout.replace("\n", " ")
    )
    assert "Traceback" not in failing.stdout + failing.stderr
