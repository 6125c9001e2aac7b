"""The gymnasium env of a scene file: spaces from the manifest, seeded resets, refused bad
actions, gymnasium's own checker, and a vector env that matches single envs."""

from __future__ import annotations

import hashlib
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import ClassVar

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from openral_eval.episode import EpisodeSpec, close_scenes, run_episode
from openral_eval.episode_frames import as_stored
from openral_eval.policies import POLICIES, PolicyEntry
from openral_eval.policy import Observation
from openral_eval.scene_env import ENV_ID, SceneEnv, make_env
from openral_eval.vector_envs import make_vector_env
from openral_eval.wave import WaveConfig
from openral_mujoco.errors import ActionRejected

from tests.conftest import ROBOTS

TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
SCENES = sorted(ROBOTS.glob("*/scenes/*.yaml"))


@pytest.fixture(scope="module")
def panda() -> Iterator[SceneEnv]:
    env = make_env(TABLETOP, seed=0, privileged=True)
    yield env
    env.close()


def _digest(env: gymnasium.Env, actions: list[np.ndarray], seed: int) -> str:  # type: ignore[type-arg]
    obs, _ = env.reset(seed=seed)
    digest = hashlib.sha256(obs["observation.state"].tobytes())
    for action in actions:
        obs, *_ = env.step(action)
        digest.update(obs["observation.state"].tobytes())
    return digest.hexdigest()


def test_spaces_follow_the_manifest(panda: SceneEnv) -> None:
    joints = [j.name for j in panda.robot.description.joints]
    space = panda.layout.space
    assert space["observation.state"].shape == (len(joints),)
    assert space["observation.velocity"].shape == (len(joints),)
    assert panda.action_names == tuple(joints)
    first = panda.robot.description.joints[0]
    assert panda.box.low[0] == first.position_limits[0]
    assert panda.box.high[0] == first.position_limits[1]
    slots = {slot.slot for slot in panda.robot.tables.vla_slots}
    images = {key.removeprefix("observation.images.") for key in space if "images" in key}
    assert images == slots and len(slots) == sum(
        s.kind == "rgb" for s in panda.robot.description.sensors
    )
    assert all("." in key and key.startswith("observation.") for key in space)  # flat, LeRobot's
    obs, info = panda.reset(seed=3)
    assert panda.observation_space.contains(obs)
    names = panda.layout.environment_names
    assert obs["observation.environment_state"].shape == (len(names),)
    assert {"red_cube_pos.0", "red_cube_pos.2"} <= set(names)
    assert info["seed"] == 3 and info["success"] is False


def test_seed_draws_the_randomisation_and_repeats(panda: SceneEnv) -> None:
    first, _ = panda.reset(seed=1)
    again, _ = panda.reset(seed=1)
    other, _ = panda.reset(seed=2)
    key = "observation.environment_state"
    np.testing.assert_array_equal(first[key], again[key])
    assert not np.array_equal(first[key], other[key])


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda a: a[:-1], "expected 8"),
        (lambda a: np.where(np.arange(a.size) == 2, np.nan, a), "action[2] (panda_joint3) is nan"),
        (lambda a: np.where(np.arange(a.size) == 0, 9.0, a), "action[0] (panda_joint1) is 9; "),
        (lambda a: [*a.tolist()[:-1], "x"], "is a str"),
    ],
)
def test_a_bad_action_is_refused_naming_its_slot_and_nothing_moves(
    panda: SceneEnv, edit: object, expected: str
) -> None:
    panda.reset(seed=0)
    good = panda.hal.hold_action()
    panda.step(good)
    before = panda.hal.read_state()
    with pytest.raises(ActionRejected, match=re.escape(expected)):
        panda.step(edit(good))  # type: ignore[operator]
    after = panda.hal.read_state()
    assert after.sim_time_s == before.sim_time_s
    np.testing.assert_array_equal(after.positions, before.positions)
    assert panda.steps == 1


def test_an_unknown_mode_or_key_is_one_clear_error() -> None:
    with pytest.raises(
        ValueError, match="unknown action mode 'ee_fly'; valid: joint_position, ee_delta_pose"
    ):
        make_env(TABLETOP, action_mode="ee_fly")
    with pytest.raises(ValueError, match=r"unknown env config keys \['sede'\]"):
        make_env(TABLETOP, sede=1)


def test_max_steps_truncates(panda: SceneEnv) -> None:
    env = SceneEnv({"scene": str(TABLETOP), "max_steps": 2}, hal=(panda.hal, panda.robot))
    env.reset(seed=0)
    hold = panda.hal.hold_action()
    assert env.step(hold)[3] is False
    assert env.step(hold)[3] is True


def test_gymnasium_make_builds_it_by_id() -> None:
    env = gymnasium.make(ENV_ID, config={"scene": str(TABLETOP), "sensors": False})
    try:
        obs, _ = env.reset(seed=0)
        assert not [key for key in obs if "images" in key] and obs["observation.state"].shape == (
            8,
        )
    finally:
        env.close()


@pytest.mark.parametrize("scene", SCENES, ids=lambda p: f"{p.parent.parent.name}/{p.stem}")
def test_gymnasium_check_env_passes(scene: Path) -> None:
    env = make_env(scene, seed=0)
    try:
        check_env(env, skip_render_check=True)
        obs, _ = env.reset(seed=0)
        assert env.observation_space.contains(obs)
    finally:
        env.close()


def test_a_vector_env_matches_single_envs_step_for_step() -> None:
    config = {"scene": str(TABLETOP), "sensors": False}
    single = make_env(TABLETOP, sensors=False, seed=0)
    rng = np.random.default_rng(7)
    space = single.box
    hold = single.hal.hold_action()
    actions = [
        np.clip(hold + rng.normal(0, 0.05, hold.shape), space.low, space.high) for _ in range(20)
    ]
    expected = [_digest(single, actions, seed) for seed in (11, 12)]
    single.close()
    vector = gymnasium.vector.AsyncVectorEnv(
        [lambda: gymnasium.make(ENV_ID, config=config)] * 2, context="fork"
    )
    try:
        obs, _ = vector.reset(seed=[11, 12])
        digests = [hashlib.sha256(obs["observation.state"][i].tobytes()) for i in range(2)]
        for action in actions:
            obs, *_ = vector.step(np.stack([action, action]))
            for i in range(2):
                digests[i].update(obs["observation.state"][i].tobytes())
    finally:
        vector.close()
    assert [d.hexdigest() for d in digests] == expected


def test_a_vector_env_with_cameras_runs_in_fresh_processes() -> None:
    """Cameras on, the workers must not be forked from a process that has rendered (the
    env's spaces come from a first env built here): make_vector_env starts them afresh."""
    vector = make_vector_env(TABLETOP, 2, sensors=["agentview"])
    try:
        obs, _ = vector.reset(seed=[1, 2])
        images = [key for key in obs if key.startswith("observation.images.")]
        assert images == ["observation.images.camera1"]  # agentview's slot, once
        assert obs[images[0]].shape == (2, 128, 128, 3)
        first = obs[images[0]].copy()
        obs, *_ = vector.step(np.stack([vector.single_action_space.sample()] * 2))
        assert obs[images[0]].std() > 5  # a picture, not a blank buffer
        assert not np.array_equal(first[0], first[1])  # two seeds, two cube placements
    finally:
        vector.close()


ASYNC_WITH_CAMERAS = """
import gymnasium, numpy as np
import openral_eval.scene_env
config = {"scene": %r, "sensors": ["agentview"]}
make = lambda: gymnasium.make("openral/Scene-v0", config=config)
vector = gymnasium.vector.AsyncVectorEnv([make] * 2)
obs, _ = vector.reset(seed=[1, 2])
frames = obs["observation.images.camera1"]
print(frames.shape, frames.std() > 5, not np.array_equal(frames[0], frames[1]))
vector.close()
"""


def test_gymnasiums_own_async_vector_env_with_cameras_forks_and_renders() -> None:
    """A user's script that never rendered: gymnasium builds a first env in it to learn the
    spaces, then forks its workers (its default start method here). The env lays out its
    spaces without rendering, so the forked workers can render."""
    done = subprocess.run(
        [sys.executable, "-c", ASYNC_WITH_CAMERAS % str(TABLETOP)],
        capture_output=True, text=True, timeout=300, env={**os.environ, "MUJOCO_GL": "egl"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split("\n")[-2] == "(2, 128, 128, 3) True True"


def test_a_robosuite_vector_env_without_cameras_observes_none_and_does_not_hang() -> None:
    """robosuite renders its scene's cameras whatever the env asks: the observation leaves
    them out when ``sensors=False``, and its workers start afresh (forked after robosuite
    opened its renderer, they waited forever)."""
    robosuite = TABLETOP.parent / "lift_robosuite.yaml"
    vector = make_vector_env(robosuite, 2, sensors=False)
    try:
        obs, _ = vector.reset(seed=[1, 2])
        assert sorted(obs) == ["observation.state", "observation.velocity"]
        obs, *_ = vector.step(np.stack([vector.single_action_space.sample()] * 2))
        assert obs["observation.state"].shape[0] == 2
    finally:
        vector.close()


def test_a_vector_env_of_no_envs_is_one_clear_error() -> None:
    with pytest.raises(ValueError, match="num_envs is 0; expected at least 1"):
        make_vector_env(TABLETOP, 0, sensors=False)


class _Recorder:
    """Hold plus seeded noise on every slot (clamped by the episode), remembering each action."""

    required_slots = ()
    needs_privileged = False
    actions: ClassVar[list[np.ndarray]] = []

    def __init__(self, config: WaveConfig) -> None:
        _Recorder.actions = []
        self.rng = np.random.default_rng(5)

    def act(self, obs: Observation) -> np.ndarray:
        hold = obs["action_spec"][1]
        action = hold + self.rng.normal(0.0, 0.05, hold.shape)
        _Recorder.actions.append(action)
        return action


def test_a_sweep_episode_is_the_env_stepped_with_the_same_actions(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(POLICIES, "recorder", PolicyEntry(WaveConfig, _Recorder))
    try:
        result = run_episode(EpisodeSpec(str(TABLETOP), 4, "recorder", (), 15))
    finally:
        close_scenes()
    assert result.error is None and result.steps == 15
    env = make_env(TABLETOP, sensors=False)
    try:
        obs, _ = env.reset(seed=4)
        digest = hashlib.sha256(obs["observation.state"].tobytes())
        for action in _Recorder.actions:
            clipped = np.clip(action, env.box.low, env.box.high)
            obs, *_ = env.step(as_stored(clipped, env.box.low, env.box.high))  # float32, as applied
            digest.update(obs["observation.state"].tobytes())
    finally:
        env.close()
    assert digest.hexdigest() == result.trajectory_sha256
