"""The process vector env gives what gymnasium's SyncVectorEnv gives for the same seeds and
actions (observations, rewards, ends, autoreset), with every env but the first in a worker
process; a worker whose env raises, or that dies, is one line, never a hang."""

from __future__ import annotations

import os
import signal
from functools import partial

import gymnasium
import numpy as np
import pytest
from openral_eval import make_process_vector_env
from openral_eval.process_env import ProcessEnv, WorkerError
from openral_eval.process_vector_env import ProcessVectorEnv
from openral_eval.scene_env import make_env

from tests.conftest import ROBOTS
from tests.eval.vector_checks import assert_same_batch, steps_like_sync_vector_env

FRANKA = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")


def test_it_steps_as_sync_vector_env_does_autoreset_included() -> None:
    config = {"sensors": False, "max_steps": 6, "reward_mode": "dense"}
    processes = make_process_vector_env(FRANKA, 3, **config)
    plain = gymnasium.vector.SyncVectorEnv([partial(make_env, FRANKA, **config)] * 3)
    try:
        assert sum(isinstance(env, ProcessEnv) for env in processes.envs) == 2
        steps_like_sync_vector_env(processes, plain)
    finally:
        processes.close()
        plain.close()
    assert not any(env._process.is_alive() for env in processes.envs[1:])


class _Breaks(gymnasium.Wrapper):  # type: ignore[type-arg]
    """Raises at its third step."""

    def __init__(self, env: gymnasium.Env) -> None:  # type: ignore[type-arg]
        super().__init__(env)
        self.steps = 0

    def step(self, action):  # type: ignore[no-untyped-def]
        self.steps += 1
        if self.steps == 3:
            raise ValueError("the third step broke")
        return super().step(action)


def _breaking() -> gymnasium.Env:  # type: ignore[type-arg]
    return _Breaks(make_env(FRANKA, sensors=False))


def test_a_worker_whose_env_raises_or_dies_is_one_line() -> None:
    local = make_env(FRANKA, sensors=False)
    spaces = (local.observation_space, local.action_space)
    env = ProcessEnv(_breaking, spaces)
    try:
        env.reset(seed=0)
        action = local.action_space.sample()
        env.step(action)
        env.step(action)
        with pytest.raises(WorkerError, match=r"raised ValueError: the third step broke"):
            env.step(action)
        env.step(action)  # the worker goes on after a failed step
        os.kill(env._process.pid, signal.SIGKILL)
        with pytest.raises(WorkerError, match=r"died \(exit code -9\)"):
            env.step(action)
    finally:
        env.close()
        local.close()


def test_the_same_step_autoreset_mode_is_refused_in_one_line() -> None:
    with pytest.raises(ValueError, match="takes the next_step or disabled autoreset mode"):
        ProcessVectorEnv(partial(make_env, FRANKA, sensors=False), 2, autoreset_mode="SameStep")
    with pytest.raises(ValueError, match="num_envs is 0"):
        make_process_vector_env(FRANKA, 0)


ORPHAN = f"""
import time
from openral_eval import make_process_vector_env

envs = make_process_vector_env({FRANKA!r}, 2, sensors=False)
envs.reset(seed=0)
print(envs.envs[1]._process.pid, flush=True)
time.sleep(60)
"""


def test_a_worker_ends_when_the_process_that_made_it_is_killed() -> None:
    import subprocess
    import sys
    import time

    maker = subprocess.Popen([sys.executable, "-c", ORPHAN], stdout=subprocess.PIPE, text=True)
    assert maker.stdout is not None
    worker = int(maker.stdout.readline())
    os.kill(worker, 0)  # alive
    maker.kill()
    maker.wait(10)
    deadline = time.monotonic() + 15.0
    while time.monotonic() < deadline:
        try:
            os.kill(worker, 0)
        except ProcessLookupError:
            return
        time.sleep(0.1)
    pytest.fail(f"worker {worker} outlived the process that made it")


class _Counting(gymnasium.Env):  # type: ignore[type-arg]
    """Infos that change on some steps and not on others, plain numbers of three types,
    then an array too (gymnasium's own batching); with ``breaks``, step 7 raises."""

    observation_space = gymnasium.spaces.Box(-1e9, 1e9, (2,), np.float64)
    action_space = gymnasium.spaces.Box(-1.0, 1.0, (1,), np.float64)

    def __init__(self, breaks: bool = False) -> None:
        self.count, self.breaks = 0, breaks

    def reset(self, *, seed=None, options=None):  # type: ignore[no-untyped-def]
        self.count = 0
        return np.zeros(2), {"seed": seed}

    def step(self, action):  # type: ignore[no-untyped-def]
        self.count += 1
        if self.breaks and self.count == 7:
            raise ValueError("the seventh step broke")
        info = {"even": self.count % 4 < 2, "quarter": self.count // 4, "x": self.count / 2}
        if self.count > 8:
            info["array"] = np.full(3, self.count)
        obs = np.array([self.count, float(action[0])])
        return obs, float(self.count), False, False, info


def test_infos_and_observations_arrive_whether_they_changed_or_not() -> None:
    """A worker sends an info again only when it changed; what arrives is what a
    SyncVectorEnv of the same envs gives, step for step."""
    processes = ProcessVectorEnv(_Counting, 3)
    plain = gymnasium.vector.SyncVectorEnv([_Counting] * 3)
    try:
        assert_same_batch(processes.reset(seed=1)[1], plain.reset(seed=1)[1])
        for step in range(1, 13):
            action = np.full((3, 1), step / 100)
            a, ra, _, _, ia = processes.step(action)
            b, rb, _, _, ib = plain.step(action)
            np.testing.assert_array_equal(a, b)
            np.testing.assert_array_equal(ra, rb)
            assert_same_batch(ia, ib)
    finally:
        processes.close()
        plain.close()


def test_an_observation_once_returned_is_never_written_again() -> None:
    """With ``copy`` (the default) every step and reset returns a batch of its own; with
    ``copy=False`` the same batch, rewritten in place, as gymnasium's own vector envs do."""
    processes = ProcessVectorEnv(_Counting, 2)
    shared = ProcessVectorEnv(_Counting, 2, copy=False)
    try:
        kept = [(obs, obs.copy()) for obs in (processes.reset(seed=0)[0],)]
        for step in range(1, 5):
            obs = processes.step(np.full((2, 1), step / 100))[0]
            kept.append((obs, obs.copy()))
        obs = processes.reset(seed=0, options={"reset_mask": np.array([True, False])})[0]
        kept.append((obs, obs.copy()))
        processes.step(np.zeros((2, 1)))
        for held, then in kept:
            np.testing.assert_array_equal(held, then)
        first = shared.reset(seed=0)[0]
        assert shared.step(np.zeros((2, 1)))[0] is first and first[0, 0] == 1.0
    finally:
        processes.close()
        shared.close()


def test_when_the_first_env_raises_the_workers_step_is_not_left_for_the_next() -> None:
    """Env 0 steps in the caller's process: its error comes through as it is, and the
    workers' results of that step are taken then, so the next step returns the next step."""
    processes = ProcessVectorEnv(partial(_Counting, breaks=True), 2)
    try:
        processes.reset(seed=1)
        for step in range(1, 10):
            if step == 7:
                with pytest.raises(ValueError, match="the seventh step broke"):
                    processes.step(np.zeros((2, 1)))
                continue
            obs, *_ = processes.step(np.full((2, 1), step / 100))
            assert obs[:, 0].tolist() == [step, step]
            assert obs[:, 1].tolist() == [step / 100] * 2
    finally:
        processes.close()
