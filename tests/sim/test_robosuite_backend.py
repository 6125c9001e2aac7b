"""The robosuite backend: Lift with the Panda and the UR5e, two cameras, built from scene files."""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterator
from pathlib import Path

from openral_core.loaded import loaded_robot

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco
import numpy as np
import pytest
from openral_cli.main import app as cli
from openral_core import load_robot_by_id
from openral_core.errors import ManifestError
from openral_core.loader import load_robot, load_scene
from openral_hal.sim_attached import SimAttachedHAL
from openral_sim.robosuite_backend import (
    RobosuiteError,
    RobosuiteRollout,
    build_robosuite_rollout,
)
from openral_sim.rollout import SimRollout
from openral_sim.scene import build_sim_env_from_yaml
from typer.testing import CliRunner

from tests.conftest import REPO

SIZE = 64
HORIZON = 5
# The Panda scene names the environment in `assets`; the UR5e scene only by its id.
SCENES = {
    "franka_panda": "id: lift_panda\n  assets: Lift",
    "ur5e": "id: lift",
}


CAMERAS = {"agentview", "wrist"}
"""The scene files' cameras (10 Hz sensors of both manifests)."""


def scene_text(robot_id: str, scene: str, options: str = f"horizon: {HORIZON}") -> str:
    return f"""schema_version: "0.1"
robot_id: {robot_id}
seed: 3
scene:
  {scene}
  backend: robosuite
  observation: {{width: {SIZE}, height: {SIZE}}}
  cameras: [agentview, wrist]
  options: {{control_freq_hz: 20.0, {options}}}
"""


def write_scene(folder: Path, robot_id: str, scene: str, options: str | None = None) -> Path:
    file = folder / f"{robot_id}.yaml"
    text = scene_text(robot_id, scene) if options is None else scene_text(robot_id, scene, options)
    file.write_text(text)
    return file


@pytest.fixture(scope="module")
def rollouts(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, RobosuiteRollout]]:
    """Both rollouts stay alive together: each must still render into its own GL context."""
    folder = tmp_path_factory.mktemp("scenes")
    built: dict[str, RobosuiteRollout] = {}
    try:
        for robot_id, scene in SCENES.items():
            rollout = build_sim_env_from_yaml(write_scene(folder, robot_id, scene))
            assert isinstance(rollout, RobosuiteRollout)
            built[robot_id] = rollout
        yield built
    finally:
        for rollout in built.values():
            rollout.close()


@pytest.fixture(params=sorted(SCENES))
def rollout(request: pytest.FixtureRequest, rollouts: dict[str, RobosuiteRollout]) -> SimRollout:
    env = rollouts[request.param]
    assert isinstance(env, SimRollout)
    return env


def test_reset_renders_both_cameras(rollout: RobosuiteRollout) -> None:
    images = rollout.reset(0).images
    assert rollout.camera_names == ("agentview", "wrist")
    assert set(images) == {"agentview", "wrist"}
    for name, image in images.items():
        assert image.dtype == np.uint8 and image.shape == (SIZE, SIZE, 3), name
        assert image.std() > 0, f"{name} is blank"
    assert not np.array_equal(images["agentview"], images["wrist"])


def test_action_dim_is_the_controllers(rollout: RobosuiteRollout) -> None:
    # default composite controllers: 6-D OSC pose + 1 gripper value for both arms
    assert rollout.action_dim == rollout.env.action_dim == 7
    low, high = rollout.action_limits
    assert low.shape == high.shape == (7,)


def test_random_steps_move_the_arm_and_the_picture(rollout: RobosuiteRollout) -> None:
    first = rollout.reset(0)
    model, data = rollout.mujoco_handles()
    qpos = data.qpos.copy()
    rng = np.random.default_rng(0)
    results = [rollout.step(rng.uniform(-1.0, 1.0, rollout.action_dim)) for _ in range(4)]
    assert not any(result.outcome.done for result in results)
    # the cameras are 10 Hz sensors on a 20 Hz loop: a frame every other step
    assert [set(result.obs.images) for result in results] == [set(), CAMERAS, set(), CAMERAS]
    result = results[-1]
    frame = result.obs.images["agentview"]
    assert not np.array_equal(frame, first.images["agentview"])
    assert not np.allclose(data.qpos, qpos)
    assert result.obs.time_s == pytest.approx(4 / 20.0)
    assert result.outcome.steps == 4
    assert model.nq == data.qpos.size


def test_same_seed_same_first_frame_and_handles_survive_reset(rollout: RobosuiteRollout) -> None:
    first = rollout.reset(7).images["agentview"]
    handles = rollout.mujoco_handles()
    rollout.step(np.ones(rollout.action_dim))
    again = rollout.reset(7).images["agentview"]
    assert np.array_equal(first, again)
    model, data = rollout.mujoco_handles()
    assert model is handles[0] and data is handles[1]


def test_horizon_truncates(rollout: RobosuiteRollout) -> None:
    rollout.reset(0)
    results = [rollout.step(np.zeros(rollout.action_dim)) for _ in range(HORIZON)]
    assert [r.outcome.truncated for r in results] == [False] * (HORIZON - 1) + [True]
    assert not any(r.outcome.terminated for r in results)


def test_panda_handles_are_raw_mujoco(rollouts: dict[str, RobosuiteRollout]) -> None:
    model, data = rollouts["franka_panda"].mujoco_handles()
    assert isinstance(model, mujoco.MjModel) and isinstance(data, mujoco.MjData)
    joints = [model.joint(i).name for i in range(model.njnt)]
    assert joints[:7] == [f"robot0_joint{i}" for i in range(1, 8)]
    obs = rollouts["franka_panda"].reset(0)
    qpos = [data.qpos[model.joint(f"robot0_joint{i}").qposadr[0]] for i in range(1, 8)]
    np.testing.assert_allclose(obs.task_state["robot0_joint_pos"], qpos)


def test_frames_match_a_plain_mujoco_render(rollout: RobosuiteRollout) -> None:
    """Each frame is what mujoco.Renderer draws of the same model and data (top row first),
    also while another rollout and a foreign GL context are alive: robosuite draws into
    whichever context is current, so the rollout must make its own current."""
    model, data = rollout.mujoco_handles()
    frames = rollout.reset(0).images
    cameras = rollout.camera_models  # from the manifests' robosuite_camera
    assert cameras == {"agentview": "agentview", "wrist": "robot0_eye_in_hand"}
    with mujoco.Renderer(model, SIZE, SIZE) as renderer:
        for name, camera in cameras.items():
            renderer.update_scene(data, camera=camera)
            reference = renderer.render().astype(float)
            # multisampling differs; an upside-down or foreign-context frame is off by > 60
            assert np.abs(frames[name] - reference).mean() < 30, name
        again = rollout.reset(0).images  # the renderer's context is current now
    for name in cameras:
        assert np.array_equal(again[name], frames[name]), name


@pytest.mark.parametrize(("robot_id", "expected"), [("franka_panda", "Panda"), ("ur5e", "UR5e")])
def test_the_robosuite_robot_comes_from_the_manifest(
    rollouts: dict[str, RobosuiteRollout], robot_id: str, expected: str
) -> None:
    sim = load_robot_by_id(robot_id).sim
    assert sim is not None and sim.robosuite_robot == expected
    assert rollouts[robot_id].env.robots[0].name == expected


def test_a_robot_without_a_robosuite_model_is_refused_at_robot_id(tmp_path: Path) -> None:
    path = write_scene(tmp_path, "so100", "id: lift")
    with pytest.raises(ManifestError) as caught:
        build_robosuite_rollout(load_scene(path))
    (line,) = str(caught.value).splitlines()
    assert line.startswith(f"{path}:2:1: robot_id: 'so100' has no robosuite model; ")
    assert "add sim.robosuite_robot of " in line and "robots/so100/robot.yaml" in line
    assert "Panda" in line  # names the classes to choose from


def test_a_robot_given_by_the_caller_is_refused_at_the_backend(tmp_path: Path) -> None:
    path = write_scene(tmp_path, "so100", "id: lift")
    path.write_text(path.read_text().replace("robot_id: so100\n", ""))
    with pytest.raises(ManifestError, match=r":5:3: scene\.backend: 'so100' has no robosuite"):
        build_robosuite_rollout(load_scene(path), load_robot_by_id("so100"))


def test_an_unknown_robosuite_robot_is_located_in_the_manifest(tmp_path: Path) -> None:
    folder = tmp_path / "franka_panda"
    folder.mkdir()
    manifest = folder / "robot.yaml"
    text = (REPO / "robots" / "franka_panda" / "robot.yaml").read_text()
    manifest.write_text(text.replace("robosuite_robot: Panda", "robosuite_robot: Pandora"))
    scene = load_scene(write_scene(tmp_path, "franka_panda", "id: lift"))
    with pytest.raises(
        ManifestError,
        match=rf"^{re.escape(str(manifest))}:\d+:\d+: "
        r"sim\.robosuite_robot: robosuite has no robot 'Pandora'",
    ):
        build_robosuite_rollout(scene, load_robot(manifest))


def test_a_camera_that_is_no_rgb_sensor_is_refused(tmp_path: Path) -> None:
    path = write_scene(tmp_path, "franka_panda", "id: lift")
    path.write_text(path.read_text().replace("[agentview, wrist]", "[agentview, eye]"))
    message = r"scene\.cameras\[1\]: 'eye' is not an rgb sensor of franka_panda; .*agentview, wrist"
    with pytest.raises(ManifestError, match=message):
        build_robosuite_rollout(load_scene(path))


@pytest.mark.parametrize(
    ("scene", "options", "message"),
    [
        ("id: tabletop", "horizon: 5", "names no robosuite environment"),
        ("id: lift", "table_height_m: 0.7", "table_height_m: applies to the native backend"),
        ("id: lift\n  assets: Lfit", "horizon: 5", "unknown robosuite environment 'Lfit'"),
        ("id: lift", "controller: NOPE", "unknown robosuite composite controller 'NOPE'"),
    ],
)
def test_scene_errors(tmp_path: Path, scene: str, options: str, message: str) -> None:
    path = write_scene(tmp_path, "franka_panda", scene, options)
    with pytest.raises(ManifestError, match=rf"^{re.escape(str(path))}:\d+:\d+: .*{message}"):
        build_robosuite_rollout(load_scene(path))


def test_wrong_action_width_is_refused(rollouts: dict[str, RobosuiteRollout]) -> None:
    env = rollouts["ur5e"]
    env.reset(0)
    with pytest.raises(RobosuiteError, match=r"expected \(7,\)"):
        env.step(np.zeros(3))


def test_nothing_lands_in_the_repository() -> None:
    """robosuite keeps its macros and numba caches in site-packages, not in our tree."""
    assert not list(REPO.glob("**/macros_private.py"))


def test_robosuite_and_native_scenes_give_the_same_joint_names() -> None:
    """Both committed Panda scenes, attached through SimAttachedHAL, read the same joints."""
    franka = load_robot_by_id("franka_panda")
    scenes = REPO / "robots" / "franka_panda" / "scenes"
    states = {}
    for name in ("lift_robosuite.yaml", "tabletop.yaml"):
        hal = SimAttachedHAL(build_sim_env_from_yaml(scenes / name), loaded_robot(franka))
        hal.connect()
        try:
            states[name] = hal.read_state()
        finally:
            hal.disconnect()
    robosuite, native = states["lift_robosuite.yaml"], states["tabletop.yaml"]
    assert robosuite.names == native.names == tuple(j.name for j in franka.joints)
    for state in (robosuite, native):  # real joint angles, not zeros: the arm starts bent
        assert np.isfinite(state.positions).all() and np.abs(state.positions).max() > 0.1


def test_sim_run_drives_the_robosuite_scene(tmp_path: Path) -> None:
    """`openral sim run` steps robosuite with its own (7-wide) action and names the joints."""
    scene = REPO / "robots" / "franka_panda" / "scenes" / "lift_robosuite.yaml"
    result = CliRunner().invoke(
        cli, ["sim", "run", "--config", str(scene), "--steps", "3", "--out", str(tmp_path)]
    )
    assert result.exit_code == 0, result.output
    assert len(sorted(tmp_path.glob("wrist_*.png"))) == 3
    last = json.loads((tmp_path / "joint_states.jsonl").read_text().splitlines()[-1])
    franka = load_robot_by_id("franka_panda")
    assert set(last["positions"]) == {joint.name for joint in franka.joints}  # manifest names


def test_a_welded_base_is_refused(tmp_path: Path) -> None:
    path = write_scene(tmp_path, "franka_panda", "id: lift")
    path.write_text(path.read_text() + "base_pose: {weld: true}\n")
    with pytest.raises(ManifestError, match=r":\d+:\d+: base_pose: robosuite environments place"):
        build_robosuite_rollout(load_scene(path))


def test_scene_file_errors_name_the_file(tmp_path: Path) -> None:
    path = write_scene(tmp_path, "so100", "id: lift")
    with pytest.raises(ManifestError, match=rf"^{re.escape(str(path))}:\d+:\d+: robot_id: 'so100'"):
        build_sim_env_from_yaml(path)
