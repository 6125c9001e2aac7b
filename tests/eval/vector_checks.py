"""The check both of this project's vector envs pass: step for step what gymnasium's
SyncVectorEnv gives for the same seeds and actions, past an autoreset."""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np


def steps_like_sync_vector_env(vector: Any, plain: gymnasium.vector.SyncVectorEnv) -> None:
    """Reset both with one seed per env, then 9 steps of the same random actions (the envs'
    limit is 6 steps: every env resets on the 7th), then a reset of the first env only;
    observations (every key), rewards, ends and infos (values, dtypes and masks) must be
    equal."""
    seeds = [3 + i for i in range(vector.num_envs)]
    a, a_info = vector.reset(seed=seeds)
    b, b_info = plain.reset(seed=seeds)
    for key in ("observation.state", "observation.tcp_pose"):
        np.testing.assert_array_equal(a[key], b[key])
    assert list(a_info["seed"]) == list(b_info["seed"]) == seeds
    vector.action_space.seed(0)
    ends = []
    for _ in range(9):
        action = vector.action_space.sample()
        a, ra, ta, ua, ia = vector.step(action)
        b, rb, tb, ub, ib = plain.step(action)
        assert_same_batch(a, b)
        np.testing.assert_array_equal(ra, rb)
        assert (ta == tb).all() and (ua == ub).all()
        assert_same_batch(ia, ib)
        ends.append(bool(ua.all()))
    assert ends == [False] * 5 + [True] + [False] * 3
    mask = np.arange(vector.num_envs) == 0
    a, a_info = vector.reset(seed=99, options={"reset_mask": mask})
    b, b_info = plain.reset(seed=99, options={"reset_mask": mask})
    assert_same_batch(a, b)
    assert_same_batch(a_info, b_info)


def assert_same_batch(mine: dict[str, Any], theirs: dict[str, Any]) -> None:
    """The same keys, in the same order, with equal arrays of the same dtype."""
    assert list(mine) == list(theirs)
    for key, value in theirs.items():
        assert mine[key].dtype == value.dtype, key
        np.testing.assert_array_equal(mine[key], value, err_msg=key)
