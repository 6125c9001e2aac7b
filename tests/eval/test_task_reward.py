"""Rewards and horizons of the shipped task scenes, through gymnasium as a trainer sees them:
``check_env`` passes in both reward modes, a scripted success gets sparse reward 1 on its
success step (0 before), the dense reward grows from each phase of ``scripted_lift`` to the
next, and episodes truncate at the horizon. Bad reward settings are refused in one line."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from pathlib import Path

import gymnasium
import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from openral_core.errors import ManifestError
from openral_core.loader import load_scene
from openral_core.paths import repo_root
from openral_core.scene_index import SceneEntry, read_scene_index
from openral_eval import episode
from openral_eval.episode import EpisodeSpec, run_episode, scene_for
from openral_eval.policy import PolicyAdapter
from openral_eval.scene_env import SceneEnv
from openral_sim.rollout import SceneRollout

from tests.conftest import ROBOTS

TASKS = [entry for entry in read_scene_index() if entry.success]
"""Every shipped scene that declares success."""


def _id(entry: SceneEntry) -> str:
    return entry.env_id


def test_every_shipped_task_scene_has_a_horizon_and_a_dense_reward() -> None:
    assert {entry.robot_id for entry in TASKS} == {"franka_panda", "panda_mobile", "so101"}
    for entry in TASKS:
        assert entry.horizon == 300 and entry.dense_reward, entry


@pytest.mark.parametrize("entry", TASKS, ids=_id)
@pytest.mark.parametrize("mode", ["sparse", "dense"])
def test_check_env_passes_in_both_reward_modes(entry: SceneEntry, mode: str) -> None:
    env = gymnasium.make(entry.env_id, reward_mode=mode, sensors=False)
    try:
        assert env.spec is not None and env.spec.max_episode_steps == entry.horizon
        check_env(env.unwrapped, skip_render_check=True)
        _, info = env.reset(seed=3)
        _, reward, _, _, info = env.step(env.action_space.sample())
        assert info["is_success"] is info["success"] is False
        assert 0.0 <= float(reward) < 1.0 and (mode == "dense" or reward == 0.0)
    finally:
        env.close()


def test_an_episode_truncates_at_the_horizon() -> None:
    env = gymnasium.make("openral/franka_panda-tabletop-v0", sensors=False)
    try:
        scene_env = env.unwrapped
        assert isinstance(scene_env, SceneEnv)
        env.reset(seed=0)
        hold = scene_env.clipped(scene_env.hal.hold_action())
        ended = []
        for step in range(1, 301):
            _, _, terminated, truncated, _ = env.step(hold)
            if terminated or truncated:
                ended.append((step, terminated, truncated))
                break
        assert ended == [(300, False, True)]
    finally:
        env.close()


@pytest.fixture
def lift_phases(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[PolicyAdapter]]:
    """The scripted_lift instances the episodes make (to read their phase each step)."""
    made: list[PolicyAdapter] = []
    real = episode.make_policy

    def recording(name: str, params: Mapping[str, str] | None = None) -> PolicyAdapter:
        made.append(real(name, params))
        return made[-1]

    monkeypatch.setattr(episode, "make_policy", recording)
    yield made


@pytest.mark.parametrize("entry", TASKS, ids=_id)
def test_a_scripted_lift_earns_more_dense_reward_each_phase_and_sparse_1_on_success(
    entry: SceneEntry, lift_phases: list[PolicyAdapter]
) -> None:
    scene = str(repo_root() / entry.file)
    hal, _ = scene_for(scene)
    rows: list[tuple[str, float, float, bool]] = []

    def watch(action: object) -> None:
        if action is not None:
            outcome, policy = hal.last_outcome, lift_phases[-1]
            phase = str(getattr(policy, "phase"))  # noqa: B009 (the lift's own state)
            rows.append((phase, outcome.dense_reward, outcome.reward, outcome.success))

    result = run_episode(EpisodeSpec(scene, 0, "scripted_lift", (), None), watch)
    assert result.error is None and result.success, result
    *before, last = rows
    assert last[3] and last[2] == 1.0 and last[1] == 1.0  # the success step
    assert all(row[2] == 0.0 and not row[3] for row in before)  # sparse: 0 until then
    assert all(0.0 <= row[1] <= 1.0 for row in rows)
    ends = {phase: dense for phase, dense, _, _ in rows}  # the value at each phase's end
    order = [ends[phase] for phase in ("approach", "descend", "close", "lift")]
    print(entry.env_id, "dense at each phase's end:", [round(v, 3) for v in order])
    assert order == sorted(order) and len(set(order)) == 4, order


def test_an_unknown_reward_mode_and_dense_without_terms_are_one_line() -> None:
    franka = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
    with pytest.raises(ValueError, match=r"^unknown reward mode 'shaped'; valid: sparse, dense$"):
        SceneEnv({"scene": str(franka), "reward_mode": "shaped", "sensors": False})
    plain = ROBOTS / "ur5e" / "scenes" / "tabletop.yaml"
    with pytest.raises(ValueError) as raised:
        SceneEnv({"scene": str(plain), "reward_mode": "dense", "sensors": False})
    assert "declares no dense reward (reward.dense)" in str(raised.value)
    assert "\n" not in str(raised.value)


def _scene_with(tmp_path: Path, old: str, new: str) -> tuple[Path, str]:
    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    assert old in text
    text = text.replace(old, new)
    folder = tmp_path / "robots" / "franka_panda" / "scenes"
    folder.mkdir(parents=True)
    (folder / "tabletop.yaml").write_text(text)
    return folder / "tabletop.yaml", text


@pytest.mark.parametrize(
    ("old", "new", "expected", "marker"),
    [
        ("{kind: grasp, object: red_cube}", "{kind: grasp, object: red_cub}",
         "no object 'red_cub' in scene.options.objects", "red_cub}"),
        ("{kind: grasp, object: red_cube}", "{kind: grasp, object: red_cube, weight: 0}",
         "expected a value > 0", "weight: 0"),
        ("{kind: grasp, object: red_cube}", "{kind: place, object: red_cube, "
         "min_m: [0.6, 0, 0.8], max_m: [0.5, 0.1, 0.9]}", "each value must be at least min_m's",
         "kind: place"),
        ("{kind: grasp, object: red_cube}", "{kind: wiggle, object: red_cube}", "wiggle",
         "wiggle"),
    ],
)  # fmt: skip
def test_a_bad_reward_term_is_located_in_the_scene_file(
    tmp_path: Path, old: str, new: str, expected: str, marker: str
) -> None:
    path, text = _scene_with(tmp_path, old, new)
    with pytest.raises(ManifestError) as raised:
        load_scene(path)
    message = str(raised.value)
    line = next(i for i, row in enumerate(text.splitlines(), 1) if marker in row)
    assert f"tabletop.yaml:{line}:" in message and expected in message, message


def test_a_reward_without_success_is_refused(tmp_path: Path) -> None:
    path, text = _scene_with(
        tmp_path,
        "success:\n  - {kind: object_above, object: red_cube, z_m: 0.825, for_s: 0.5}",
        "",
    )
    with pytest.raises(ManifestError) as raised:
        load_scene(path)
    line = next(i for i, row in enumerate(text.splitlines(), 1) if row.startswith("reward:"))
    assert f"tabletop.yaml:{line}:" in str(raised.value)
    assert "a reward needs success" in str(raised.value)


def test_the_dense_terms_follow_the_state() -> None:
    """reach falls off with the TCP's distance; lift counts nothing while the cube is not
    held, however high it is; success is worth 1."""
    scene = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    hal, _ = scene_for(scene)
    hal.env_reset_seed = 0
    hal.reset()
    native = hal.env
    assert isinstance(native, SceneRollout) and native.task.dense is not None
    dense, (model, data) = native.task.dense, native.mujoco_handles()
    cube = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "scene_red_cube")

    def reach_only() -> float:
        tcp = dense._tcp.position(data)  # type: ignore[union-attr]
        gap = float(np.linalg.norm(tcp - data.xpos[cube]))
        return (1.0 - math.tanh(10.0 * gap)) / 3.0  # one of three equal weights

    assert dense.value(data, False) == pytest.approx(reach_only())
    z = int(model.jnt_qposadr[model.body_jntadr[cube]]) + 2
    data.qpos[z] += 0.10  # far above the success height, nowhere near the fingers
    mujoco.mj_forward(model, data)
    assert dense.value(data, False) == pytest.approx(reach_only())  # no lift, no grasp
    assert dense.value(data, True) == 1.0
    hal.reset()
