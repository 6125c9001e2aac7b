"""The threaded vector env gives what gymnasium's SyncVectorEnv gives for the same seeds and
actions (observations, rewards, ends, autoreset), with every env stepped on its own thread."""

from __future__ import annotations

import threading
from functools import partial

import gymnasium
import pytest
from openral_eval import make_thread_vector_env
from openral_eval.scene_env import make_env
from openral_eval.thread_vector_env import ThreadVectorEnv

from tests.conftest import ROBOTS
from tests.eval.vector_checks import steps_like_sync_vector_env

FRANKA = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")


def test_it_steps_as_sync_vector_env_does_autoreset_included() -> None:
    config = {"sensors": False, "max_steps": 6, "reward_mode": "dense"}
    threaded = make_thread_vector_env(FRANKA, 2, **config)
    plain = gymnasium.vector.SyncVectorEnv([partial(make_env, FRANKA, **config)] * 2)
    try:
        steps_like_sync_vector_env(threaded, plain)
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
