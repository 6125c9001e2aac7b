"""A policy's mode and needs in a sweep: one acting in ``ee_pose`` runs as in the env (it
failed every episode before, "valid: joint_position, ee_delta_pose"); a policy that does not
fit its scene is refused once, before any episode, in one line with exit code 2; actions
outside the action space are counted per episode (``clamped_steps``)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
from openral_eval.episode import EpisodeSpec, env_for, run_episode
from openral_eval.policies import make_policy
from openral_eval.policy import PolicyConfigError, action_mode
from openral_eval.policy_fit import check_policy_fits

from tests.conftest import REPO, ROBOTS

OPENRAL = REPO / ".venv" / "bin" / "openral"

POLICY = '''
import numpy as np


class Rise:
    """Hold the TCP's start pose 8 cm higher, the gripper open."""

    action_mode = "ee_pose"
    required_slots = ()
    needs_privileged = False

    def __init__(self):
        self.target = None

    def act(self, obs):
        if self.target is None:
            start = np.asarray(obs["observation.tcp_pose"], dtype=np.float64)
            self.target = np.concatenate([start[:3] + [0.0, 0.0, 0.08], start[3:], [1.0]])
        return self.target


class Fly(Rise):
    action_mode = "ee_fly"


class Blind(Rise):
    action_mode = "joint_position"
    required_slots = ("camera9",)


class Overreach:
    """Joint 1 five radians past where it is: outside every limit, every step."""

    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        action = np.array(obs["action_spec"][1], dtype=np.float64)
        action[0] += 5.0
        return action


class Still(Overreach):
    """The hold: inside the space."""

    def act(self, obs):
        return np.array(obs["action_spec"][1], dtype=np.float64)
'''


def test_an_ee_pose_policy_moves_the_tcp_in_a_sweep_episode(tmp_path: Path) -> None:
    policy = tmp_path / "rise.py"
    policy.write_text(POLICY)
    scene = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    spec = EpisodeSpec(scene, 0, f"{policy}:Rise", (), 40)
    env = env_for(spec, (), "ee_pose")
    start = env.tcp_pose() if env.reset(seed=0) else None
    result = run_episode(spec)
    assert result.error is None and result.steps == 40, result
    end = env.tcp_pose()
    assert start is not None and end is not None
    assert end[2] - start[2] == pytest.approx(0.08, abs=0.005)
    np.testing.assert_allclose(end[:2], start[:2], atol=0.005)
    with pytest.raises(PolicyConfigError, match="declares action_mode 'ee_fly'; valid: "):
        action_mode(make_policy(f"{policy}:Fly"))


def test_a_policy_that_does_not_fit_its_scene_is_one_line_before_any_episode(
    tmp_path: Path,
) -> None:
    policy = tmp_path / "rise.py"
    policy.write_text(POLICY)
    ur5e = str(ROBOTS / "ur5e" / "scenes" / "tabletop.yaml")  # no gripper, no sim.tcp
    with pytest.raises(
        PolicyConfigError, match=r"acts in ee_pose, which needs .*\(ur5e\) has none"
    ):
        check_policy_fits(make_policy(f"{policy}:Rise"), "Rise", ur5e)
    franka = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    with pytest.raises(PolicyConfigError, match=r"needs camera slots \['camera9'\]"):
        check_policy_fits(make_policy(f"{policy}:Blind"), "Blind", franka)
    command = [str(OPENRAL), "sim", "sweep", "--config", ur5e, "--seeds", "0:3"]
    command += ["--policy", f"{policy}:Rise", "--out", str(tmp_path / "out")]
    env = {**os.environ, "COLUMNS": "400"}
    result = subprocess.run(command, capture_output=True, text=True, timeout=120, env=env)
    assert result.returncode == 2, result.stderr
    assert "Invalid value for --policy" in result.stderr and "acts in ee_pose" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "out" / "episodes.jsonl").exists()


def test_actions_outside_the_space_are_counted_per_episode(tmp_path: Path) -> None:
    policy = tmp_path / "over.py"
    policy.write_text(POLICY)
    scene = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    result = run_episode(EpisodeSpec(scene, 0, f"{policy}:Overreach", (), 6))
    assert result.error is None and result.steps == 6 and result.clamped_steps == 6
    calm = run_episode(EpisodeSpec(scene, 0, f"{policy}:Still", (), 6))
    assert calm.error is None and calm.clamped_steps == 0
