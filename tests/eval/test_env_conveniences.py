"""What a gymnasium user expects of the env beyond its spaces: ``gymnasium.make`` takes the
config's fields as keyword arguments, ``render()`` gives a frame whenever it is asked,
``ee_pose`` has finite bounds to sample from, and an env left open exits quietly."""

from __future__ import annotations

import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from openral_eval.scene_env import SceneEnv

from tests.conftest import REPO, ROBOTS

FRANKA = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")


def test_make_takes_config_fields_as_keyword_arguments() -> None:
    env = gymnasium.make(
        "openral/Scene-v0", scene=FRANKA, action_mode="ee_delta_pose", sensors=False
    )
    try:
        scene_env = env.unwrapped
        assert isinstance(scene_env, SceneEnv)
        assert scene_env.config.action_mode.value == "ee_delta_pose"
        assert scene_env.action_names[-1] == "gripper"
    finally:
        env.close()
    with pytest.raises(ValueError, match=r"unknown env config keys \['colour'\]"):
        gymnasium.make("openral/Scene-v0", scene=FRANKA, colour="red")


def test_render_draws_the_scene_as_it_is_even_without_sensors() -> None:
    seen = SceneEnv({"scene": FRANKA}, render_mode="rgb_array")
    blind = SceneEnv({"scene": FRANKA, "sensors": False}, render_mode="rgb_array")
    try:
        obs, _ = seen.reset(seed=4)
        blind.reset(seed=4)
        frame = blind.render()
        assert frame is not None and frame.shape == (128, 128, 3) and frame.dtype == np.uint8
        assert frame.std() > 5.0  # a picture, not a blank
        np.testing.assert_array_equal(frame, obs["observation.images.camera1"])  # agentview
        hold = blind.clipped(blind.hal.hold_action())
        hold[0] += 0.5
        for _ in range(10):
            blind.step(hold)
        assert np.abs(blind.render().astype(int) - frame.astype(int)).mean() > 0.5  # type: ignore[union-attr]
    finally:
        seen.close()
        blind.close()


@pytest.mark.parametrize("scene", ["franka_panda", "so101", "panda_mobile"])
def test_ee_pose_bounds_are_finite_and_hold_what_the_arm_reaches(scene: str) -> None:
    path = ROBOTS / scene / "scenes" / "tabletop.yaml"
    env = SceneEnv({"scene": str(path), "action_mode": "ee_pose", "sensors": False, "seed": 0})
    try:
        low, high = env.action_space.low, env.action_space.high
        assert np.isfinite(low).all() and np.isfinite(high).all()
        assert (high[:3] - low[:3]).max() < 5.0  # an arm's reach, not the world
        tcp = env.tcp_pose()
        assert tcp is not None and np.all((low[:3] < tcp[:3]) & (tcp[:3] < high[:3]))
        env.reset(seed=1)
        for _ in range(5):  # a sampled action is one the env takes
            env.step(env.action_space.sample())
    finally:
        env.close()


def test_an_env_left_open_exits_without_a_traceback() -> None:
    script = (
        "import gymnasium, openral_eval.scene_env\n"
        "env = gymnasium.make('openral/franka_panda-tabletop-v0', render_mode='rgb_array')\n"
        "env.reset(seed=0)\n"
        "env.render()\n"
        "print('done')\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO, timeout=180
    )
    assert run.returncode == 0 and run.stdout.strip() == "done", run.stderr
    assert "Traceback" not in run.stderr and "Exception ignored" not in run.stderr, run.stderr
