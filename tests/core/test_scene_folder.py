"""A scene under ``robots/<id>/scenes/`` belongs to robot ``<id>``: a copied robot folder
never silently simulates the robot it was copied from."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest
from openral_core import ManifestError, load_scene
from openral_core.loader import scene_folder_robot

from tests.conftest import ROBOTS

UR5E_SCENE = ROBOTS / "ur5e" / "scenes" / "tabletop.yaml"


def copy_robot(tmp_path: Path, new_id: str) -> Path:
    """``cp -r robots/ur5e <tmp>/robots/<new_id>`` with ``name:`` renamed; the folder."""
    folder = tmp_path / "robots" / new_id
    shutil.copytree(ROBOTS / "ur5e", folder)
    manifest = folder / "robot.yaml"
    manifest.write_text(manifest.read_text().replace("name: ur5e\n", f"name: {new_id}\n", 1))
    return folder


def without_robot_id(text: str) -> str:
    assert text.count("robot_id: ur5e\n") == 1
    return text.replace("robot_id: ur5e\n", "")


def test_a_copied_folder_refuses_the_old_robot_id_at_its_line(tmp_path: Path) -> None:
    scene = copy_robot(tmp_path, "my_ur5e") / "scenes" / "tabletop.yaml"
    line = scene.read_text().splitlines().index("robot_id: ur5e") + 1
    with pytest.raises(ManifestError) as caught:
        load_scene(scene)
    assert str(caught.value) == (
        f"{scene}:{line}:1: robot_id: must be 'my_ur5e', the robot whose folder "
        "robots/my_ur5e/scenes/ holds this scene, or be left out; got 'ur5e'"
    )


def test_a_scene_in_a_robot_folder_may_leave_robot_id_out(tmp_path: Path) -> None:
    scene = copy_robot(tmp_path, "my_ur5e") / "scenes" / "tabletop.yaml"
    scene.write_text(without_robot_id(scene.read_text()))
    assert load_scene(scene).robot_id == "my_ur5e"
    scene.write_text("robot_id: my_ur5e\n" + scene.read_text())
    assert load_scene(scene).robot_id == "my_ur5e"


def test_a_scene_elsewhere_keeps_what_it_says(tmp_path: Path) -> None:
    anonymous = tmp_path / "tabletop.yaml"
    anonymous.write_text(without_robot_id(UR5E_SCENE.read_text()))
    assert load_scene(anonymous).robot_id is None
    named = tmp_path / "scenes" / "named.yaml"  # a scenes/ folder, but not under robots/
    named.parent.mkdir()
    shutil.copy(UR5E_SCENE, named)
    assert load_scene(named).robot_id == "ur5e"


def test_the_folder_is_read_from_the_resolved_path(tmp_path: Path) -> None:
    scenes = copy_robot(tmp_path, "my_ur5e") / "scenes"
    assert scene_folder_robot(scenes / "tabletop.yaml") == "my_ur5e"
    assert scene_folder_robot(scenes / ".." / ".." / "ur5e_other.yaml") is None
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    assert scene_folder_robot(outside / ".." / "robots" / "x" / "scenes" / "s.yaml") == "x"
    link = tmp_path / "link"
    link.symlink_to(scenes, target_is_directory=True)
    assert scene_folder_robot(link / "tabletop.yaml") == "my_ur5e"
    with pytest.raises(ManifestError, match="must be 'my_ur5e'"):
        load_scene(link / "tabletop.yaml")


def test_sim_run_of_a_copied_folder_stops_with_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from openral_cli.main import run

    scene = copy_robot(tmp_path, "my_ur5e") / "scenes" / "tabletop.yaml"
    monkeypatch.setattr(sys, "argv", ["openral", "sim", "run", "--config", str(scene)])
    with pytest.raises(SystemExit) as stop:
        run()
    assert stop.value.code == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"error: {scene}:4:1: robot_id: must be")


def test_a_robot_given_with_a_scene_for_another_is_refused() -> None:
    from openral_sim.scene import scene_robot

    with pytest.raises(ManifestError) as caught:
        scene_robot(load_scene(UR5E_SCENE), "franka_panda")
    assert str(caught.value) == (
        f"{UR5E_SCENE}:4:1: robot_id: the scene is for ur5e, not franka_panda"
    )
