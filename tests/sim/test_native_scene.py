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
from openral_sim.native_scene import SceneError
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
        first = env.reset(0)["images"]
        assert set(first) == set(env.camera_names) and first
        handles = env.mujoco_handles()
        assert handles is not None and env.action_dim == handles[0].nu
        hold = handles[1].ctrl.copy()
        for step in range(6):
            last = env.step(hold + 0.2 * (step + 1) / 6).obs["images"]
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
    assert "joint1" in json.loads(lines[-1])["positions"]


def test_a_camera_the_robot_does_not_have_is_an_error(tmp_path: Path) -> None:
    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    bad = tmp_path / "scene.yaml"
    bad.write_text(text.replace("cameras: [agentview, wrist]", "cameras: [agentview, belly]"))
    with pytest.raises(SceneError, match="'belly' is not a camera sensor"):
        build_sim_env_from_yaml(bad)


def test_an_invalid_scene_file_reports_file_line_and_field(tmp_path: Path) -> None:
    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    bad = tmp_path / "scene.yaml"
    bad.write_text(text.replace("backend: native", "backend: unreal"))
    with pytest.raises(ManifestError) as caught:
        build_sim_env_from_yaml(bad)
    line = text.splitlines().index("  backend: native") + 1
    assert f"{bad}:{line}:3: scene.backend: expected one of native, robosuite" in str(caught.value)
