"""Policies named by file or module (``--policy my_policy.py:Wave``, ``pkg.mod:Class``):
built with their config's parameters, refused in one line when they cannot be, and a
policy that hangs, exits or crashes its process costs only its episode, from the CLI."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from openral_eval.policies import make_policy
from openral_eval.policy import PolicyConfigError
from openral_eval.wave import WavePolicy

from tests.conftest import REPO, ROBOTS
from tests.eval.hostile_policy import CALM_STEPS

OPENRAL = Path(sys.executable).parent / "openral"
TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
HOSTILE = "tests/eval/hostile_policy.py"
POLICY_FILE = """
from dataclasses import dataclass
import numpy as np

@dataclass(frozen=True)
class Config:
    gain: float = 1.0

class Scaled:
    config_type = Config
    required_slots = ()
    needs_privileged = False

    def __init__(self, config):
        self.config = config

    def act(self, obs):
        return self.config.gain * np.asarray(obs["action_spec"][1])

class Plain:
    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        return np.asarray(obs["action_spec"][1])
"""


@pytest.fixture
def policy_file(tmp_path: Path) -> Path:
    path = tmp_path / "mine.py"
    path.write_text(POLICY_FILE)
    return path


def _obs() -> dict[str, object]:
    hold = np.array([1.0, 2.0])
    return {"observation.state": hold, "action_spec": (("a", "b"), hold)}


def test_a_class_in_a_file_is_built_with_its_parameters(policy_file: Path) -> None:
    scaled = make_policy(f"{policy_file}:Scaled", {"gain": "0.5"})
    assert scaled.act(_obs()).tolist() == [0.5, 1.0]  # type: ignore[arg-type]
    plain = make_policy(f"{policy_file}:Plain")
    assert plain.act(_obs()).tolist() == [1.0, 2.0]  # type: ignore[arg-type]
    with pytest.raises(PolicyConfigError, match="unknown parameter 'gain'"):
        make_policy(f"{policy_file}:Plain", {"gain": "2"})


def test_a_class_in_a_module_is_built_as_its_registered_name_is() -> None:
    policy = make_policy("openral_eval.wave:WavePolicy", {"amplitude": "0.3"})
    assert isinstance(policy, WavePolicy) and policy.config.amplitude == 0.3


@pytest.mark.parametrize(
    ("reference", "words"),
    [
        ("{dir}/absent.py:Wave", "no file"),
        ("{file}:Missing", "defines no class Missing; its classes: Config, Plain, Scaled"),
        ("{file}:", "expected FILE.py:CLASS or package.module:CLASS"),
        ("no_such_module_xyz:Wave", "does not import (ModuleNotFoundError"),
        ("{file}:Config", "lacks required_slots, needs_privileged, act"),
    ],
)
def test_a_reference_that_cannot_be_built_is_one_line(
    policy_file: Path, reference: str, words: str
) -> None:
    name = reference.format(dir=policy_file.parent, file=policy_file)
    with pytest.raises(PolicyConfigError) as refused:
        make_policy(name)
    assert words in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.parametrize(
    ("policy", "workers", "error"),
    [
        ("Hangs", "2", "timeout: still running after 3 s of wall time; its worker was stopped"),
        ("Exits", "1", "its worker process died, every time it ran"),
        ("Crashes", "2", "its worker process died, every time it ran"),
        ("Hangs", "ray", "timeout: still running after 3 s of wall time; its worker was stopped"),
        ("Raises", "2", "RuntimeError: the policy broke (hostile_policy.py:"),
    ],
)
def test_a_policy_that_breaks_its_process_costs_only_its_episode(
    tmp_path: Path, policy: str, workers: str, error: str
) -> None:
    command = [str(OPENRAL), "sim", "sweep", "--config", str(TABLETOP), "--seeds", "0:2"]
    where = ["--ray", "local", "--workers", "2"] if workers == "ray" else ["--workers", workers]
    command += ["--policy", f"{HOSTILE}:{policy}", *where, "--video", "none"]
    command += ["--episode-timeout", "3", "--out", str(tmp_path / "out")]
    env = {**os.environ, "COLUMNS": "200"}
    result = subprocess.run(command, capture_output=True, text=True, cwd=REPO, env=env, timeout=120)
    assert result.returncode == 1, result.stderr  # every episode failed: exit 1, after the report
    assert "Traceback" not in result.stderr
    rows = [
        json.loads(line) for line in (tmp_path / "out" / "episodes.jsonl").read_text().splitlines()
    ]
    assert sorted(row["seed"] for row in rows) == [0, 1]
    assert all(row["error"].startswith(error) for row in rows), rows
    # what each got through is recorded: its calm steps (Ray's stopped worker tells none),
    # and its wall time (a stopped one: at least its limit)
    calm = 0 if workers == "ray" and policy == "Hangs" else CALM_STEPS
    assert [row["steps"] for row in rows] == [calm, calm], rows
    assert all(row["wall_time_s"] >= (3.0 if policy == "Hangs" else 0.01) for row in rows), rows
    assert (tmp_path / "out" / "summary.json").is_file()
