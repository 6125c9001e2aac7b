"""The native backend builds every robot's default scene; `openral sim run` records it."""

from __future__ import annotations

import json
import os
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np
import pytest
from openral_cli.main import app
from openral_core import ManifestError, robot_ids
from openral_core.errors import OpenralError
from openral_sim.rollout import SimRollout
from openral_sim.scene import build_sim_env_from_yaml
from typer.testing import CliRunner

from tests.conftest import ROBOTS

runner = CliRunner()
DEFAULT_SCENES = [ROBOTS / r / "scenes" / "tabletop.yaml" for r in robot_ids()]


@pytest.mark.parametrize("scene", DEFAULT_SCENES, ids=lambda p: p.parent.parent.name)
def test_every_default_scene_renders_its_cameras_and_moves(scene: Path) -> None:
    env = build_sim_env_from_yaml(scene)
    try:
        assert isinstance(env, SimRollout)
        first = env.reset(0).images
        assert set(first) == set(env.camera_names) and first
        handles = env.mujoco_handles()
        assert handles is not None and env.action_dim == len(env.action_names)  # type: ignore[attr-defined]
        hold = env.hold_action()  # type: ignore[attr-defined]
        for step in range(6):
            last = env.step(hold + 0.2 * (step + 1) / 6).obs.images
        for name, image in first.items():
            assert image.dtype == np.uint8 and image.shape == (128, 128, 3)
            assert image.std() > 5, f"{name} is blank"
        moved = max(np.abs(last[n].astype(int) - first[n].astype(int)).mean() for n in first)
        assert moved > 0.5, "no camera saw anything move"
        assert np.isfinite(handles[1].qpos).all()
    finally:
        env.close()


def test_sim_run_writes_frames_and_joint_states(tmp_path: Path) -> None:
    scene = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
    result = runner.invoke(
        app, ["sim", "run", "--config", str(scene), "--steps", "5", "--out", str(tmp_path)]
    )
    assert result.exit_code == 0, result.output
    for camera in ("agentview", "wrist"):
        frames = sorted(tmp_path.glob(f"{camera}_*.png"))
        assert len(frames) == 5
        assert frames[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = (tmp_path / "joint_states.jsonl").read_text().splitlines()
    assert len(lines) == 5
    assert "panda_joint1" in json.loads(lines[-1])["positions"]  # manifest names, not MJCF


def test_a_camera_the_robot_does_not_have_is_an_error(tmp_path: Path) -> None:
    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    bad = tmp_path / "scene.yaml"
    bad.write_text(text.replace("cameras: [agentview, wrist,", "cameras: [agentview, belly,"))
    with pytest.raises(ManifestError) as info:
        build_sim_env_from_yaml(bad)
    (issue,) = info.value.issues
    assert (issue.file, issue.field) == (bad, "scene.cameras[1]")
    assert issue.line > 1 and issue.column > 1
    assert "'belly' is not a camera sensor of robot 'franka_panda'" in issue.message


def test_an_invalid_scene_file_reports_file_line_and_field(tmp_path: Path) -> None:
    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    bad = tmp_path / "scene.yaml"
    bad.write_text(text.replace("backend: native", "backend: unreal"))
    with pytest.raises(ManifestError) as caught:
        build_sim_env_from_yaml(bad)
    line = text.splitlines().index("  backend: native") + 1
    assert f"{bad}:{line}:3: scene.backend: expected one of native, robosuite" in str(caught.value)


def _root_position(env: SimRollout) -> np.ndarray:
    handles = env.mujoco_handles()
    assert handles is not None
    model, data = handles
    free = [j for j in range(model.njnt) if model.jnt_type[j] == 0]  # mjJNT_FREE
    robot_free = max(free, key=lambda j: model.jnt_qposadr[j])  # objects come first
    address = model.jnt_qposadr[robot_free]
    return np.array(data.qpos[address : address + 3])


def _humanoid_scene(tmp_path: Path, weld: bool, robot: str = "g1") -> Path:
    path = tmp_path / f"{robot}_{weld}.yaml"
    text = (ROBOTS / "g1" / "scenes" / "tabletop.yaml").read_text()
    text = text.replace("robot_id: g1", f"robot_id: {robot}")
    text = text.replace(
        "position_m: [0.0, 0.0, 0], yaw_deg: 0.0, weld: true",
        f"position_m: [0.3, -0.2, 0], yaw_deg: 90.0, weld: {str(weld).lower()}",
    )
    assert "yaw_deg: 90.0" in text
    path.write_text(text)
    return path


def test_a_welded_floating_base_stays_where_the_scene_puts_it(tmp_path: Path) -> None:
    """The free objects come before the robot in qpos; the robot's base still lands at
    base_pose (not a cube), and the weld holds it there while a loose one falls over."""
    heights = {}
    for weld in (True, False):
        env = build_sim_env_from_yaml(_humanoid_scene(tmp_path, weld))
        try:
            env.reset(0)
            start = _root_position(env)
            np.testing.assert_allclose(start[:2], [0.3, -0.2], atol=1e-4)  # after settling
            crouch = env.hold_action() + 0.6  # type: ignore[attr-defined]
            for _ in range(40):  # two seconds of a pose no one can stand in
                env.step(crouch)
            heights[weld] = (start[2], _root_position(env)[2])
        finally:
            env.close()
    held, loose = heights[True], heights[False]
    assert abs(held[1] - held[0]) < 0.02
    assert loose[0] - loose[1] > 0.2  # without the weld the humanoid falls


def test_welding_a_fixed_base_is_an_error(tmp_path: Path) -> None:
    path = _humanoid_scene(tmp_path, True, robot="ur5e")
    path.write_text(path.read_text().replace("cameras: [head]", "cameras: [agentview]"))
    with pytest.raises(ManifestError, match=r":\d+:\d+: base_pose\.weld: .* has a fixed base"):
        build_sim_env_from_yaml(path)


def test_a_scene_for_an_unknown_robot_names_the_file(tmp_path: Path) -> None:
    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    bad = tmp_path / "scene.yaml"
    bad.write_text(text.replace("robot_id: franka_panda", "robot_id: nobot"))
    with pytest.raises(OpenralError, match=r"scene\.yaml:\d+:\d+: robot_id: unknown robot 'nobot'"):
        build_sim_env_from_yaml(bad)


@pytest.mark.parametrize("axis", ["+x", "-x", "+y", "-y", "+z", "-z"])
def test_a_mounted_camera_looks_along_its_mount_axis(axis: str) -> None:
    from openral_sim.scene_cameras import looking_along

    position, xyaxes = looking_along(axis)
    right, up = np.array(xyaxes[:3]), np.array(xyaxes[3:])
    look = -np.cross(right, up)  # a MuJoCo camera looks along its -z
    expected = np.zeros(3)
    expected["xyz".index(axis[1])] = 1.0 if axis[0] == "+" else -1.0
    np.testing.assert_allclose(look, expected, atol=1e-12)
    assert abs(float(np.dot(right, up))) < 1e-12
    np.testing.assert_allclose(np.array(position) @ expected, 0.0, atol=1e-12)  # beside it
