"""Default scene pictures a policy can use, for every robot.

- A fixed camera the scene places (a sensor with neither ``camera`` nor ``mount_body``) has
  the whole robot and every object near it in its picture: every corner of the bounding
  box of each visible robot geom, in the pose a reset leaves, and of each object within
  ``WORK_RANGE_M`` of the robot projects inside the image (pinhole projection with the
  compiled camera's pose and fovy; no rendering). Checked in every native scene file of
  ``robots/``, and for every robot with a fixed camera added to its default scene
  (humanoids, the mobile and the bimanual robots have none of their own).
- A camera on the robot sees the table, and a wrist camera its own hand (segmentation
  render of each default scene).
- No camera of any native scene file is blown out or black (the frames a reset renders).
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_core import open_robot
from openral_core.loader import load_scene
from openral_core.models import Backend, RobotDescription
from openral_mujoco.robot_bodies import robot_bodies
from openral_sim.camera_framing import FRAME_MARGIN, WORK_RANGE_M, fit_view
from openral_sim.native_scene import NativeScene
from openral_sim.scene_cameras import FORWARD_LOOKING
from openral_sim.scene_geometry import geom_corners

from tests.conftest import ROBOTS

SCENE_FILES = sorted(
    path
    for path in ROBOTS.glob("*/scenes/*.yaml")
    if load_scene(path).scene.backend is Backend.native
)
DEFAULT_SCENES = sorted(ROBOTS.glob("*/scenes/tabletop.yaml"))
SATURATED = 250
"""A pixel is saturated when any of its channels is at least this [0-255]."""
MAX_SATURATED = 0.02
"""Largest share of saturated pixels in any frame."""
LUMINANCE = (40.0, 200.0)
"""Bounds of a frame's mean luminance (Rec. 601 weights) [0-255]."""
MIN_TABLE = 0.05
"""Least share of a robot camera's pixels that show the table."""
MIN_HAND = 0.005
"""Least share of a wrist camera's pixels that show its body or the bodies below it (for a
robot with a gripper: the fingers or jaws)."""


def _scene_id(path: Path) -> str:
    return f"{path.parent.parent.name}/{path.stem}"


@dataclass
class Built:
    """A scene after a reset: its model and data, and the frames the reset rendered."""

    env: NativeScene
    images: dict[str, npt.NDArray[np.uint8]]


@pytest.fixture(scope="module")
def built() -> Iterator[Callable[[Path, Path | None], Built]]:
    """Build (once per module) and reset the scene of a file, for its robot (or the manifest
    given); the renderers are freed at once, the model and data kept."""
    scenes: dict[tuple[Path, Path | None], Built] = {}

    def get(scene_file: Path, manifest: Path | None = None) -> Built:
        key = (scene_file, manifest)
        if key not in scenes:
            scene = load_scene(scene_file)
            manifest_file = manifest or ROBOTS / str(scene.robot_id) / "robot.yaml"
            env = NativeScene(scene, open_robot(manifest_file))
            images = env.reset(0).images
            env.close()
            scenes[key] = Built(env, images)
        return scenes[key]

    yield get


def _project(
    model: mujoco.MjModel, data: mujoco.MjData, camera: int, points: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Pinhole projection into a camera with a vertical fovy of ``model.cam_fovy`` and
    an image of height 1: (right, up, depth) with right/up in half-heights from the centre."""
    relative = (points - data.cam_xpos[camera]) @ data.cam_xmat[camera].reshape(3, 3)
    depth = -relative[:, 2]
    scale = math.tan(math.radians(model.cam_fovy[camera]) / 2) * depth
    return relative[:, 0] / scale, relative[:, 1] / scale, depth


def _framed(
    model: mujoco.MjModel, data: mujoco.MjData, robot: RobotDescription, scene_file: Path
) -> npt.NDArray[np.float64]:
    """Corners of the visible robot geoms and of the objects within reach (the scene's
    objects and the model's own loose bodies) that a fixed camera must show."""
    visible = (model.geom_group < 3) & (model.geom_rgba[:, 3] > 0)
    on_robot = np.isin(model.geom_bodyid, list(robot_bodies(model, robot)))
    points = [geom_corners(model, data, np.flatnonzero(visible & on_robot))]
    low, high = points[0].min(axis=0) - WORK_RANGE_M, points[0].max(axis=0) + WORK_RANGE_M
    options = load_scene(scene_file).scene.options
    named = {f"scene_{o.name}" for o in (options.objects if options and options.objects else [])}
    for body in range(1, model.nbody):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
        geoms = np.flatnonzero(visible & ~on_robot & (model.geom_bodyid == body))
        if len(geoms) and (name in named or model.body_weldid[body] != 0):
            corners = geom_corners(model, data, geoms)
            if ((corners >= low) & (corners <= high)).all():
                points.append(corners)
    return np.concatenate(points)


def _cameras(env: NativeScene) -> dict[str, tuple[int, int, int]]:
    """Sensor name -> (camera id, image width, image height) of every camera the scene
    renders, RGB (at the scene's observation size) and depth (at the sensor's)."""
    height, width = env.image_size
    cameras = {
        name: (mujoco.mj_name2id(env.model, mujoco.mjtObj.mjOBJ_CAMERA, mjcf), width, height)
        for name, mjcf in env.camera_models.items()
    }
    for name, depth in env.depth_cameras.items():
        cameras[name] = (depth.camera_id, depth.width, depth.height)
    return cameras


def _check_framing(built: Built, scene_file: Path, label: str) -> list[str]:
    """Names of the scene-placed fixed cameras checked; fails on any point outside."""
    env = built.env
    model, data, robot = env.model, env.data, env.robot.description
    sensors = {s.name: s for s in robot.sensors}
    points = _framed(model, data, robot, scene_file)
    checked = []
    for name, (camera, width, height) in _cameras(env).items():
        sensor = sensors[name]
        if getattr(sensor, "camera", None) is not None or sensor.mount_body is not None:
            continue
        assert model.body_weldid[model.cam_bodyid[camera]] == 0, f"{name} is not fixed"
        right, up, depth = _project(model, data, camera, points)
        aspect = width / height
        outside = (np.abs(right) > aspect) | (np.abs(up) > 1) | (depth <= 0)
        assert not outside.any(), (
            f"{label}: {outside.sum()} of {len(points)} corners of the robot "
            f"and its objects are outside camera {name!r}'s picture"
        )
        # tight: something comes within twice the margin of an edge (not a far-off camera)
        fill = max(np.abs(right).max() / aspect, np.abs(up).max())
        assert fill > 1 - 2 * FRAME_MARGIN, f"{label}: {name} is {fill:.0%} filled, too far"
        checked.append(name)
    return checked


@pytest.mark.parametrize("scene_file", SCENE_FILES, ids=_scene_id)
def test_fixed_cameras_show_the_whole_robot_and_its_objects(
    built: Callable[[Path, Path | None], Built], scene_file: Path
) -> None:
    _check_framing(built(scene_file, None), scene_file, _scene_id(scene_file))


@pytest.mark.parametrize("scene_file", DEFAULT_SCENES, ids=_scene_id)
def test_a_fixed_camera_added_to_any_robot_frames_it(
    built: Callable[[Path, Path | None], Built], scene_file: Path, tmp_path: Path
) -> None:
    """A copy of the robot's manifest with one more camera, ``overview`` (neither camera
    nor mount body), rendered by a copy of its default scene."""
    robot_id = scene_file.parent.parent.name
    folder = tmp_path / robot_id
    shutil.copytree(ROBOTS / robot_id, folder)  # with the model files a manifest may name
    text = (ROBOTS / robot_id / "robot.yaml").read_text()
    overview = "  - {name: overview, kind: rgb, width: 128, height: 128, rate_hz: 10.0, "
    overview += "frame_id: overview_optical_frame}\n"
    assert text.count("\nsensors:\n") == 1
    (folder / "robot.yaml").write_text(text.replace("\nsensors:\n", "\nsensors:\n" + overview))
    scene_text = scene_file.read_text()
    assert scene_text.count("cameras: [") == 1
    variant = tmp_path / "scene.yaml"
    variant.write_text(scene_text.replace("cameras: [", "cameras: [overview, "))
    checked = _check_framing(built(variant, folder / "robot.yaml"), variant, robot_id)
    assert "overview" in checked


def _table(model: mujoco.MjModel, data: mujoco.MjData, robot: RobotDescription) -> int:
    """The geom the first loose object that is no part of the robot rests on."""
    robot_ids = robot_bodies(model, robot)
    loose = [b for b in range(1, model.nbody) if model.body_weldid[b] != 0 and b not in robot_ids]
    assert loose, "the default scene has no object on a table"
    found = np.array([-1], dtype=np.int32)
    down = np.array([0.0, 0.0, -1.0])
    mujoco.mj_ray(model, data, data.xpos[loose[0]], down, None, 1, loose[0], found)
    assert found[0] >= 0
    return int(found[0])


def _below(model: mujoco.MjModel, body: int) -> npt.NDArray[np.bool_]:
    """Per body: ``body`` itself or a body below it in the tree."""
    below = np.zeros(model.nbody, dtype=bool)
    below[body] = True
    for child in range(body + 1, model.nbody):  # a parent's id is below its children's
        below[child] = below[model.body_parentid[child]]
    return below


@pytest.mark.parametrize("scene_file", DEFAULT_SCENES, ids=_scene_id)
def test_cameras_on_the_robot_see_the_table_and_wrist_cameras_the_hand(
    built: Callable[[Path, Path | None], Built], scene_file: Path
) -> None:
    env = built(scene_file, None).env
    model, data = env.model, env.data
    table = _table(model, data, env.robot.description)
    moving = {
        name: spec
        for name, spec in _cameras(env).items()
        if model.body_weldid[model.cam_bodyid[spec[0]]] != 0
    }
    assert moving, "no camera rides on the robot"
    for name, (camera, width, height) in moving.items():
        with mujoco.Renderer(model, height, width) as renderer:
            renderer.enable_segmentation_rendering()
            renderer.update_scene(data, camera=camera)
            ids, kinds = np.moveaxis(renderer.render(), -1, 0)
        geoms = np.where(kinds == mujoco.mjtObj.mjOBJ_GEOM, ids, -1)
        shown = (geoms == table).mean()
        assert shown >= MIN_TABLE, f"{name} shows the table in {shown:.1%} of its pixels"
        body = int(model.cam_bodyid[camera])
        body_name = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or "").lower()
        if any(word in body_name for word in FORWARD_LOOKING):
            continue  # a head camera: the hands need not be in its view
        wiring = env.robot.tables.hal_wiring
        if wiring is None or not wiring.grippers:
            continue  # no gripper: a tool camera looks past the bare flange it rides on
        hand = _below(model, body)[model.geom_bodyid[np.maximum(geoms, 0)]] & (geoms >= 0)
        assert hand.mean() >= MIN_HAND, f"{name} shows its hand in {hand.mean():.1%}"


@pytest.mark.parametrize("scene_file", SCENE_FILES, ids=_scene_id)
def test_no_camera_is_blown_out_or_dark(
    built: Callable[[Path, Path | None], Built], scene_file: Path
) -> None:
    images = built(scene_file, None).images
    assert images
    for name, image in images.items():
        saturated = (image >= SATURATED).any(axis=2).mean()
        luminance = (image @ np.array([0.299, 0.587, 0.114])).mean()
        assert saturated <= MAX_SATURATED, f"{name}: {saturated:.1%} of its pixels saturated"
        assert LUMINANCE[0] <= luminance <= LUMINANCE[1], f"{name}: mean luminance {luminance:.0f}"


def test_fit_view_keeps_every_point_inside_and_touches_an_edge() -> None:
    rng = np.random.default_rng(0)
    for aspect in (1.0, 4 / 3, 0.5):
        points = rng.normal(size=(200, 3)) * [0.5, 0.3, 0.8] + [0.3, -0.2, 1.0]
        direction = np.array([1.0, 0.3, 0.55])
        eye, rotation = fit_view(points, direction, 50.0, aspect)
        assert np.allclose(rotation.T @ rotation, np.eye(3))
        np.testing.assert_allclose(rotation[:, 2], direction / np.linalg.norm(direction))
        local = (points - eye) @ rotation
        scale = math.tan(math.radians(25.0)) * (1 - FRAME_MARGIN) * -local[:, 2]
        right, up = np.abs(local[:, 0]) / (scale * aspect), np.abs(local[:, 1]) / scale
        assert (local[:, 2] < 0).all() and right.max() <= 1 + 1e-9 and up.max() <= 1 + 1e-9
        assert max(right.max(), up.max()) == pytest.approx(1.0)
        # centred: the extreme points on either side of the axis that binds reach its edges
        binding = right if right.max() > up.max() else up
        signed = local[:, 0] / (scale * aspect) if binding is right else local[:, 1] / scale
        assert signed.max() == pytest.approx(1.0) and signed.min() == pytest.approx(-1.0)
