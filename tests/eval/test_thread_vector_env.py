"""The threaded vector env gives what gymnasium's SyncVectorEnv gives for the same seeds and
actions (observations, rewards, ends, autoreset), with every env stepped on its own thread."""

from __future__ import annotations

import threading
from functools import partial

import gymnasium
import numpy as np
import pytest
from openral_eval import make_thread_vector_env
from openral_eval.scene_env import make_env
from openral_eval.thread_vector_env import ThreadVectorEnv

from tests.conftest import ROBOTS

FRANKA = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")


def test_it_steps_as_sync_vector_env_does_autoreset_included() -> None:
    config = {"sensors": False, "max_steps": 6, "reward_mode": "dense"}
    threaded = make_thread_vector_env(FRANKA, 2, **config)
    plain = gymnasium.vector.SyncVectorEnv([partial(make_env, FRANKA, **config)] * 2)
    try:
        a, a_info = threaded.reset(seed=[3, 4])
        b, b_info = plain.reset(seed=[3, 4])
        np.testing.assert_array_equal(a["joint_positions"], b["joint_positions"])
        assert list(a_info["seed"]) == list(b_info["seed"]) == [3, 4]
        threaded.action_space.seed(0)
        ends = []
        for _ in range(9):  # past the 6-step limit: both envs reset on the 7th step
            action = threaded.action_space.sample()
            a, ra, ta, ua, _ = threaded.step(action)
            b, rb, tb, ub, _ = plain.step(action)
            np.testing.assert_array_equal(a["joint_positions"], b["joint_positions"])
            np.testing.assert_array_equal(ra, rb)
            assert (ta == tb).all() and (ua == ub).all()
            ends.append(bool(ua.all()))
        assert ends == [False] * 5 + [True] + [False] * 3
    finally:
        threaded.close()
        plain.close()


def test_each_env_steps_on_a_thread_of_its_own() -> None:
    seen: list[str] = []

    class Spy(gymnasium.Wrapper):  # type: ignore[type-arg]
        def step(self, action):  # type: ignore[no-untyped-def]
            seen.append(threading.current_thread().name)
            return super().step(action)

    envs = ThreadVectorEnv([lambda: Spy(make_env(FRANKA, sensors=False))] * 2)
    try:
        envs.reset(seed=0)
        envs.step(envs.action_space.sample())
        assert len(seen) == 2 and all(name.startswith("openral-env") for name in seen)
    finally:
        envs.close()
    with pytest.raises(ValueError, match="num_envs is 0; expected at least 1"):
        make_thread_vector_env(FRANKA, 0)
    two = make_thread_vector_env(FRANKA, 2, sensors=False)
    try:
        with pytest.raises(ValueError, match="1 seeds for 2 envs"):
            two.reset(seed=[1])
    finally:
        two.close()
