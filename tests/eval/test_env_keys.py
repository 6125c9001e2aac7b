"""The env's observation by key: ``keys`` keeps the keys named, ``flat`` joins them in key
order into one vector (robosuite's ``GymWrapper``), with :attr:`FlatLayout.slices` saying
where each is; a key the scene does not have is one line naming the valid ones; gymnasium's
checker passes on both forms."""

from __future__ import annotations

import re

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from openral_eval.scene_env import make_env

from tests.conftest import ROBOTS

FRANKA = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
KEPT = ("observation.tcp_pose", "observation.state")


def test_keys_keep_only_the_keys_named() -> None:
    env = make_env(FRANKA, sensors=False, keys=KEPT)
    try:
        obs, _ = env.reset(seed=1)
        assert sorted(obs) == sorted(KEPT) and sorted(env.observation_space.spaces) == sorted(KEPT)
        check_env(env, skip_render_check=True)
    finally:
        env.close()


def test_flat_is_the_kept_keys_in_key_order_as_one_vector() -> None:
    keyed = make_env(FRANKA, sensors=False, keys=KEPT)
    flat = make_env(FRANKA, sensors=False, keys=KEPT, flat=True)
    try:
        by_key, _ = keyed.reset(seed=2)
        vector, _ = flat.reset(seed=2)
        assert flat.flat is not None and vector.shape == flat.observation_space.shape == (15,)
        assert list(flat.flat.slices) == sorted(KEPT)
        for key, where in flat.flat.slices.items():
            np.testing.assert_array_equal(vector[where], by_key[key])
        action = flat.hal.hold_action()
        action[0] += 0.2
        for _ in range(5):
            by_key, *_ = keyed.step(action)
            vector, *_ = flat.step(action)
        np.testing.assert_array_equal(
            vector[flat.flat.slices["observation.state"]], by_key["observation.state"]
        )
        check_env(flat, skip_render_check=True)
    finally:
        keyed.close()
        flat.close()


def test_one_key_alone_is_a_tuple_of_one() -> None:
    env = make_env(FRANKA, sensors=False, keys="observation.state", flat=True)
    try:
        assert env.observation_space.shape == (8,)
    finally:
        env.close()


@pytest.mark.parametrize("keys", [("observation.nope",), ()], ids=["unknown", "none"])
def test_a_key_the_scene_lacks_is_one_line_naming_the_valid_ones(keys: tuple[str, ...]) -> None:
    with pytest.raises(ValueError) as refused:
        make_env(FRANKA, sensors=False, keys=keys)
    line = str(refused.value)
    assert "\n" not in line and "are not in this scene's observation" in line
    assert re.search(
        r"valid: \['observation.state', 'observation.velocity'\]|valid: \[.*'observation.state'",
        line,
    )
