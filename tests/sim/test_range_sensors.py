"""A native scene's lidar and depth camera on the mobile Panda: a wall placed 2.000 m in
front of the lidar reads 2.000 m, nothing in range reads +inf, the robot's own base (which
the lidar sits against) is never seen, and a manifest lidar without a site is refused."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_cli.main import app
from openral_core import ManifestError, open_robot
from openral_core.loader import load_scene
from openral_sim.native_scene import NativeScene
from typer.testing import CliRunner

from tests.conftest import ROBOTS

MOBILE = ROBOTS / "panda_mobile"
SCENE = """schema_version: "0.1"
robot_id: panda_mobile
base_pose: {{position_m: [0.0, 0.0, 0.0], yaw_deg: 0.0}}
scene:
  id: wall_ahead
  backend: native
  assets: floor
  observation: {{width: 64, height: 64}}
  cameras: [head_depth]
  options:
    control_freq_hz: 20.0
    objects:
      - {{name: wall, shape: box, size_m: [0.05, 1.5, 0.6], position_m: [{x}, {y}, 0.6],
         free: false}}
"""


def _scene(folder: Path, wall_face_x: float, wall_y: float = 0.0) -> NativeScene:
    path = folder / f"wall_{wall_face_x:.4f}.yaml"
    path.write_text(SCENE.format(x=wall_face_x + 0.05, y=wall_y))
    env = NativeScene(load_scene(path), open_robot(MOBILE / "robot.yaml"))
    env.reset(0)
    return env


@pytest.fixture(scope="module")
def wall_ahead(tmp_path_factory: pytest.TempPathFactory) -> Iterator[NativeScene]:
    """The base at the origin and a wall whose near face is 2.000 m ahead of the lidar."""
    folder = tmp_path_factory.mktemp("range")
    probe = _scene(folder, 5.0, wall_y=50.0)  # where is the lidar? (wall far away)
    site = mujoco.mj_name2id(probe.model, mujoco.mjtObj.mjOBJ_SITE, "base_lidar_site")
    origin = probe.data.site_xpos[site].copy()
    probe.close()
    env = _scene(folder, origin[0] + 2.0, wall_y=origin[1])
    yield env
    env.close()


def test_the_wall_2_m_ahead_reads_2_m_and_open_space_reads_inf(wall_ahead: NativeScene) -> None:
    scanner = wall_ahead.range_sensors.lidars["base_lidar"]
    ranges = wall_ahead.range_sensors.scan("base_lidar", wall_ahead.data)
    angles = scanner.angle_min + scanner.angle_increment * np.arange(len(ranges))
    centre = int(np.argmin(np.abs(angles)))
    expected = 2.0 / math.cos(angles[centre])
    assert ranges[centre] == pytest.approx(expected, abs=0.005)
    assert abs(expected - 2.0) < 1e-4  # the centre ray is within 0.6 deg of straight ahead
    beside = np.abs(angles) > math.radians(80)  # the wall is 3 m wide, 2 m ahead: not there
    assert np.isposinf(ranges[beside]).all()


def test_the_lidar_never_sees_its_own_base(wall_ahead: NativeScene) -> None:
    ranges = wall_ahead.range_sensors.scan("base_lidar", wall_ahead.data)
    finite = ranges[np.isfinite(ranges)]
    assert finite.min() >= 2.0 - 0.005  # only the wall: the base behind the site is left out
    model = wall_ahead.model
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "base_lidar_site")
    body = int(model.site_bodyid[site])
    seen_by_mj_ray = np.array([-1], np.int32)
    backwards = -wall_ahead.data.site_xmat[site].reshape(3, 3)[:, 0]
    mujoco.mj_ray(
        model,
        wall_ahead.data,
        wall_ahead.data.site_xpos[site],
        backwards,
        None,
        True,
        -1,
        seen_by_mj_ray,
    )
    assert model.body_rootid[model.geom_bodyid[seen_by_mj_ray[0]]] == model.body_rootid[body]


def test_the_depth_cloud_sees_the_wall_not_the_robot(wall_ahead: NativeScene) -> None:
    frame = wall_ahead.depth_frame("head_depth", wall_ahead.data)
    assert len(frame.points) > 100
    assert set(wall_ahead.depth_cameras) == {"head_depth"}
    assert "head_depth" not in wall_ahead.camera_names  # depth sensors render no RGB frames


def test_a_lidar_whose_site_the_scene_lacks_is_refused_at_its_field(tmp_path: Path) -> None:
    folder = tmp_path / "panda_mobile"
    folder.mkdir()
    text = (MOBILE / "robot.yaml").read_text()
    assert text.count("    site: base_lidar_site\n    mount_body: base\n") == 1
    text = text.replace("    site: base_lidar_site\n    mount_body: base\n", "    site: nowhere\n")
    text = text.replace("    mount_position_m: [0.17, 0.0, 0.25]\n", "")
    (folder / "robot.yaml").write_text(text)
    scene = load_scene(MOBILE / "scenes" / "room.yaml")
    with pytest.raises(ManifestError, match=r"robot\.yaml:\d+:\d+: sensors\[2\]\.site: .*nowhere"):
        NativeScene(scene, open_robot(folder / "robot.yaml"))


def test_sim_run_on_the_room_records_every_stream(tmp_path: Path) -> None:
    room = MOBILE / "scenes" / "room.yaml"
    command = ["sim", "run", "--config", str(room), "--steps", "2", "--out", str(tmp_path)]
    result = CliRunner().invoke(app, command)
    assert result.exit_code == 0, result.output
    names = {path.name for path in tmp_path.iterdir()}
    assert {"wrist_0001.png", "head_depth_0001.depth.png", "head_depth_0001.points.npy"} <= names
    lines = (tmp_path / "base_lidar.scan.jsonl").read_text().splitlines()
    assert len(lines) == 2
    scan = json.loads(lines[1])
    ranges = np.array([float(r) for r in scan["ranges"]])
    assert scan["step"] == 1 and scan["time"] > 0 and len(ranges) == 270
    assert np.isfinite(ranges).all()  # walls all round, within 10 m
    assert ranges.min() >= 0.05 and ranges.max() <= 10.0
    assert len(np.load(tmp_path / "head_depth_0001.points.npy")) > 100
