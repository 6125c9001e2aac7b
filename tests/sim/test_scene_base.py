"""Tests for scene_base.py: panda_mobile's arm on its Omron base in a native scene: one robot
of base and arm, the arm's own model unchanged, fixed walls and table, the sensors the
manifest mounts on the base, and the base's MJCF in the compiled-model cache key."""

from __future__ import annotations

import math
import shutil
from collections.abc import Iterator
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import load_scene, open_robot
from openral_core.loaded import open_robot_by_id
from openral_core.models import LidarSensor
from openral_mujoco.mjcf_confinement import ALLOW_OUTSIDE_ENV
from openral_mujoco.mjcf_uri import resolve_mjcf_uri
from openral_mujoco.model_cache import CACHE_ENV
from openral_mujoco.robot_bodies import robot_bodies, root_body
from openral_sim.lidar_scan import LidarScanner
from openral_sim.native_scene import NativeScene

from tests.conftest import ROBOTS

MOBILE = ROBOTS / "panda_mobile"
ROOM = MOBILE / "scenes" / "room.yaml"
BASE_URI = "pkg:robosuite/robosuite/models/assets/bases/omron_mobile_base.xml"


@pytest.fixture(scope="module")
def room() -> Iterator[NativeScene]:
    scene = NativeScene(load_scene(ROOM), open_robot_by_id("panda_mobile"))
    scene.reset(0)
    yield scene
    scene.close()


def _id(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    index = mujoco.mj_name2id(model, kind, name)
    assert index >= 0, f"{name} is not in the model"
    return int(index)


def _names(model: mujoco.MjModel, bodies: object) -> set[str]:
    return {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or "" for b in bodies}  # type: ignore[attr-defined]


def test_the_base_carries_the_arm_and_both_are_the_robot(room: NativeScene) -> None:
    model, body = room.model, mujoco.mjtObj.mjOBJ_BODY
    description = room.robot.description
    assert root_body(model, description) == _id(model, body, "base")
    assert room.base_frame == "base"
    mine = _names(model, robot_bodies(model, description))
    assert {"base", "support", "wheeled_base", "link0", "hand"} <= mine
    assert not any(name.startswith("scene_") for name in mine)
    assert model.body_parentid[_id(model, body, "link0")] == _id(model, body, "support")
    assert model.body_parentid[_id(model, body, "base")] == 0


def test_the_arm_keeps_its_own_model_and_addresses(room: NativeScene) -> None:
    arm = mujoco.mjtObj.mjOBJ_JOINT
    joint1, lift = _id(room.model, arm, "joint1"), _id(room.model, arm, "joint_torso_height")
    assert room.model.jnt_qposadr[joint1] == room.model.jnt_qposadr[lift] + 1  # after the base
    assert room.action_names == tuple(j.name for j in room.robot.description.joints)
    positions = room.joint_state().positions
    np.testing.assert_allclose(positions[:7], room.hold_action()[:7], atol=0.01)


def test_walls_and_table_are_fixed_and_the_cubes_loose(room: NativeScene) -> None:
    model = room.model
    for name in ("wall_north", "wall_south", "wall_east", "wall_west", "table"):
        body = _id(model, mujoco.mjtObj.mjOBJ_BODY, f"scene_{name}")
        assert model.body_jntnum[body] == 0 and model.body_weldid[body] == 0
    for name in ("red_cube", "green_cube"):
        joint = _id(model, mujoco.mjtObj.mjOBJ_JOINT, f"scene_{name}_joint")
        assert model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE


def test_the_base_stands_on_the_floor_at_the_base_pose(room: NativeScene) -> None:
    model, data = room.model, room.data
    floor = _id(model, mujoco.mjtObj.mjOBJ_GEOM, "scene_floor")
    base = _id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    assert model.geom_pos[floor, 2] == 0.0
    np.testing.assert_allclose(data.xpos[base], [-1.0, 0.0, 0.0], atol=1e-3)
    link0 = _id(model, mujoco.mjtObj.mjOBJ_BODY, "link0")
    assert data.xpos[link0, 2] == pytest.approx(0.70, abs=0.01)


def test_the_sensors_mounted_on_the_base_see_the_room(room: NativeScene) -> None:
    model, data = room.model, room.data
    camera = _id(model, mujoco.mjtObj.mjOBJ_CAMERA, "openral_head_depth")
    np.testing.assert_allclose(model.cam_pos[camera], [-0.1, 0.3, 1.6])
    frame = room.depth_frame("head_depth", data)
    assert np.isfinite(frame.depth_m).mean() > 0.7 and len(frame.points) > 1000
    assert room.render_cameras(data, ["wrist"])["wrist"].std() > 5
    lidar = next(s for s in room.robot.description.sensors if isinstance(s, LidarSensor))
    site = _id(model, mujoco.mjtObj.mjOBJ_SITE, lidar.site)
    assert model.site_bodyid[site] == _id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    scanner = LidarScanner(model, lidar, robot_bodies(model, room.robot.description))
    ranges = scanner.scan(data)
    ahead = int(np.argmin(np.abs(np.linspace(-135.0, 135.0, lidar.width))))
    # the table's near face is at x = 0.2, the lidar at x = -1.0 + 0.17
    assert ranges[ahead] == pytest.approx(1.03, abs=0.01)
    assert np.isfinite(ranges).all(), "the walls close the room in every direction"


def _base_copy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """panda_mobile with its base model copied to its folder (``file:`` URI, meshes linked to
    the installed ones, so the confinement check is switched off)."""
    folder = tmp_path / "panda_mobile"
    shutil.copytree(MOBILE, folder)
    installed = resolve_mjcf_uri(BASE_URI)
    (folder / "omron.xml").write_text(installed.read_text())
    (folder / "meshes").symlink_to(installed.parent / "meshes")
    manifest = folder / "robot.yaml"
    manifest.write_text(manifest.read_text().replace(BASE_URI, "file:omron.xml"))
    monkeypatch.setenv(ALLOW_OUTSIDE_ENV, "1")
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    return manifest, folder / "omron.xml"


def _yaw_gain(manifest: Path) -> float:
    scene = NativeScene(load_scene(ROOM), open_robot(manifest), render_observations=False)
    try:
        yaw = _id(scene.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "actuator_mobile_yaw")
        return float(scene.model.actuator_gainprm[yaw, 0])
    finally:
        scene.close()


def test_editing_the_base_model_compiles_the_scene_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    manifest, base = _base_copy(tmp_path, monkeypatch)
    assert _yaw_gain(manifest) == 1500.0
    assert len(list((tmp_path / "cache").glob("*.mjb"))) == 3  # arm, base, scene
    text = base.read_text()
    assert text.count('kv="1500"') == 1
    base.write_text(text.replace('kv="1500"', 'kv="1400"'))
    assert _yaw_gain(manifest) == 1400.0
    assert not math.isnan(_yaw_gain(manifest))
