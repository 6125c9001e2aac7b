"""``osc_lift`` on robosuite's Lift (``lift_robosuite.yaml``): the environment's own success
check reaches the episode's result, so a sweep on a robosuite scene can succeed.

Seeds move the cube (robosuite's placement sampler); the policy reads the task state the
backend reports and drives robosuite's default operational-space controller.
"""

from __future__ import annotations

import numpy as np
import pytest
from openral_eval.episode import EpisodeResult, EpisodeSpec, run_episode
from openral_eval.policies import PolicyConfigError, make_policy
from openral_eval.sweep import run_pool

from tests.conftest import ROBOTS
from tests.fuzz.stages import time_limit

SCENE = str(ROBOTS / "franka_panda" / "scenes" / "lift_robosuite.yaml")


def test_it_lifts_the_cube_and_robosuite_says_so_in_a_pool_and_here() -> None:
    """Three seeds in a pool of two workers (robosuite's GL context cannot cross a fork:
    this hung before the pool started its workers from a fresh process), then one of them
    again in this process: the same trajectory."""
    specs = [EpisodeSpec(SCENE, seed, "osc_lift", (), 150) for seed in (0, 1, 2)]
    results: list[EpisodeResult] = []
    with time_limit(240.0):
        run_pool(specs, 2, results.append)
    results.sort(key=lambda r: r.seed)
    assert all(r.error is None for r in results), [r.error for r in results if r.error]
    assert all(r.success for r in results), [(r.seed, r.steps) for r in results]
    assert all(r.steps < 150 for r in results)  # ended by the success check, not the limit
    again = run_episode(specs[1])
    assert again.trajectory_sha256 == results[1].trajectory_sha256


def test_a_zero_action_never_succeeds() -> None:
    result = run_episode(EpisodeSpec(SCENE, 0, "wave", (("amplitude", "0.0"),), 20))
    assert result.error is None and not result.success and result.steps == 20


def test_without_task_state_it_says_what_it_needs() -> None:
    policy = make_policy("osc_lift")
    assert policy.needs_privileged is True and policy.required_slots == ()
    obs = {
        "observation.state": np.zeros(8),
        "action_spec": (tuple(f"env_action[{i}]" for i in range(7)), np.zeros(7)),
        "time_s": 0.0,
        "task_state": {"robot0_eef_pos": np.zeros(3)},
    }
    with pytest.raises(PolicyConfigError, match=r"needs task state \('cube_pos'"):
        policy.act(obs)  # type: ignore[arg-type]
