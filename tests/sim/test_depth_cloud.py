"""Depth sensors of a native scene: metric depth, a cloud in the robot's base frame that
matches ray-cast truth, and never a point on or within 1 cm of the robot itself.

The scene is the franka tabletop seen by the manifest's ``front_depth`` camera: a fixed
camera the scene frames around the robot, so the arm fills part of the view, and the
tabletop's 5 cm red cube sits in front of it.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Iterator
from pathlib import Path

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_cli.main import app
from openral_core import open_robot
from openral_core.loader import load_scene
from openral_sim.depth_cloud import focal_length_px, near_any, pixel_rays
from openral_sim.native_scene import NativeScene
from typer.testing import CliRunner

from tests.conftest import ROBOTS

PROBE = "      - {name: probe, shape: sphere, size_m: [0.0005], position_m: [3.0, 3.0, 0.01]}\n"
VISIBLE = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8)
"""Geom groups the renderer draws by default (what a camera sees)."""


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(manifest, scene file): the franka, and its tabletop seen by its depth camera only,
    with a tiny probe sphere parked far away (see ``_closest_robot_surface``)."""
    folder = tmp_path_factory.mktemp("depth")
    scene_text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    listed = "cameras: [agentview, wrist, front_depth]"
    assert scene_text.count(listed) == 1
    scene_text = scene_text.replace(listed, "cameras: [front_depth]")
    scene_text = scene_text.replace("    objects:\n", "    objects:\n" + PROBE)
    (folder / "tabletop.yaml").write_text(scene_text)
    return ROBOTS / "franka_panda" / "robot.yaml", folder / "tabletop.yaml"


@pytest.fixture(scope="module")
def scene(files: tuple[Path, Path]) -> Iterator[NativeScene]:
    manifest, scene_file = files
    env = NativeScene(load_scene(scene_file), open_robot(manifest))
    env.reset(0)
    yield env
    env.close()


def _to_base(env: NativeScene, world: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    body = mujoco.mj_name2id(env.model, mujoco.mjtObj.mjOBJ_BODY, env.base_frame)
    rotation = env.data.xmat[body].reshape(3, 3)
    local: npt.NDArray[np.float64] = (world - env.data.xpos[body]) @ rotation
    return local


def _cast(env: NativeScene) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Ray-cast truth: the world point and geom hit through every pixel centre (-1: none)."""
    camera = env.depth_cameras["front_depth"]
    rays = camera._rays.reshape(-1, 3)
    rotation = env.data.cam_xmat[camera.camera_id].reshape(3, 3)
    directions = rays @ rotation.T
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    origin = env.data.cam_xpos[camera.camera_id].copy()
    geoms = np.full(len(directions), -1, dtype=np.int32)
    hits = np.full((len(directions), 3), np.nan)
    for index, direction in enumerate(directions):
        found = np.array([-1], dtype=np.int32)
        distance = mujoco.mj_ray(env.model, env.data, origin, direction, VISIBLE, True, -1, found)
        if found[0] >= 0:
            geoms[index], hits[index] = found[0], origin + distance * direction
    return hits, geoms


def test_depth_is_metric_and_nan_outside_the_range(scene: NativeScene) -> None:
    frame = scene.depth_frame("front_depth", scene.data)
    assert frame.depth_m.shape == (120, 160) and frame.depth_m.dtype == np.float32
    finite = frame.depth_m[np.isfinite(frame.depth_m)]
    assert finite.size > 0.5 * frame.depth_m.size
    assert finite.min() >= 0.1 and finite.max() <= 4.0
    hits, geoms = _cast(scene)
    camera = scene.depth_cameras["front_depth"]
    optical = (
        -(hits - scene.data.cam_xpos[camera.camera_id])
        @ (scene.data.cam_xmat[camera.camera_id].reshape(3, 3)[:, 2])
    )
    both = np.isfinite(frame.depth_m.ravel()) & (geoms >= 0)
    error = np.abs(frame.depth_m.ravel()[both] - optical[both])
    assert np.median(error) < 0.002  # rasterised depth agrees with ray casting


def test_a_cube_appears_where_it_is(scene: NativeScene) -> None:
    cube = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_GEOM, "scene_red_cube_geom")
    half = scene.model.geom_size[cube]
    assert np.allclose(half, 0.025)  # a 5 cm cube
    hits, geoms = _cast(scene)
    truth = _to_base(scene, hits[geoms == cube])
    assert len(truth) > 20, "the camera should see the cube"
    points = scene.depth_frame("front_depth", scene.data).points.astype(np.float64)
    world = _from_base(scene, points)
    rotation = scene.data.geom_xmat[cube].reshape(3, 3)
    local = (world - scene.data.geom_xpos[cube]) @ rotation  # in the cube's own frame
    on_cube = points[np.all(np.abs(local) <= half + 0.003, axis=1)]
    assert abs(len(on_cube) - len(truth)) <= 0.1 * len(truth)
    assert np.linalg.norm(on_cube.mean(axis=0) - truth.mean(axis=0)) < 0.01


def test_the_cloud_never_shows_the_robot(scene: NativeScene) -> None:
    camera = scene.depth_cameras["front_depth"]
    with mujoco.Renderer(scene.model, camera.height, camera.width) as renderer:
        _, geoms = camera.render(renderer, scene.data)
    robot_pixels = (geoms >= 0) & camera.robot_geoms[np.maximum(geoms, 0)]
    assert robot_pixels.mean() > 0.05, "the arm should fill part of the view"
    points = scene.depth_frame("front_depth", scene.data).points
    assert len(points) > 1000, "the cloud should keep the table and the scene"
    world = _from_base(scene, points.astype(np.float64))
    assert _closest_robot_surface(scene, world, camera.robot_geoms) >= 0.01


def test_near_any_is_exact_at_the_margin() -> None:
    rng = np.random.default_rng(0)
    others = rng.uniform(-0.1, 0.1, (500, 3)).astype(np.float32)
    points = rng.uniform(-0.12, 0.12, (2000, 3)).astype(np.float32)
    brute = (np.linalg.norm(points[:, None] - others[None], axis=2) < 0.01).any(axis=1)
    np.testing.assert_array_equal(near_any(points, others, 0.01), brute)
    assert brute.any() and not brute.all()


def _from_base(env: NativeScene, points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    body = mujoco.mj_name2id(env.model, mujoco.mjtObj.mjOBJ_BODY, env.base_frame)
    world: npt.NDArray[np.float64] = points @ env.data.xmat[body].reshape(3, 3).T
    world += env.data.xpos[body]
    return world


def _closest_robot_surface(
    env: NativeScene, world: npt.NDArray[np.float64], robot_geoms: npt.NDArray[np.bool_]
) -> float:
    """Smallest distance [m] from any of ``world`` to a visible robot geom (MuJoCo's geom
    distance to a 0.5 mm probe sphere, plus its radius; a mesh counts as its convex hull,
    which is never farther than the mesh, so the result never overstates the distance)."""
    model, data = env.model, mujoco.MjData(env.model)
    data.qpos[:] = env.data.qpos
    probe = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "scene_probe_geom")
    joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "scene_probe_joint")
    address = int(model.jnt_qposadr[joint])
    visible = robot_geoms & (model.geom_group < 3) & (model.geom_rgba[:, 3] > 0)
    mujoco.mj_kinematics(model, data)
    centres, radii = data.geom_xpos[visible].copy(), model.geom_rbound[visible]
    geoms = np.flatnonzero(visible)
    closest = np.inf
    for point in world:
        reach = np.linalg.norm(centres - point, axis=1) - radii
        nearby = geoms[reach < 0.02]
        if not len(nearby):
            continue
        data.qpos[address : address + 3] = point
        mujoco.mj_kinematics(model, data)
        for geom in nearby:
            gap = mujoco.mj_geomDistance(model, data, probe, int(geom), 0.05, None)
            closest = min(closest, gap + 0.0005)
    return closest


def test_sim_run_writes_depth_in_millimetres_and_clouds(
    files: tuple[Path, Path], tmp_path: Path
) -> None:
    manifest, scene_file = files
    command = ["sim", "run", "--config", str(scene_file), "--manifest", str(manifest)]
    command += ["--steps", "2", "--motion", "hold", "--out", str(tmp_path)]
    result = CliRunner().invoke(app, command)
    assert result.exit_code == 0, result.output
    assert "front_depth" in result.output
    millimetres = _read_png16(tmp_path / "front_depth_0001.depth.png")
    points = np.load(tmp_path / "front_depth_0001.points.npy")
    env = NativeScene(load_scene(scene_file), open_robot(manifest))  # the same two steps
    try:
        env.reset(0)
        for _ in range(2):
            env.step(env.hold_action())
        frame = env.depth_frame("front_depth", env.data)
    finally:
        env.close()
    expected = np.rint(np.nan_to_num(frame.depth_m.astype(np.float64)) * 1000)
    np.testing.assert_array_equal(millimetres, expected)  # 0 where there is no reading
    np.testing.assert_array_equal(points, frame.points)


def _read_png16(path: Path) -> npt.NDArray[np.float64]:
    """A 16-bit greyscale PNG written unfiltered, decoded with zlib alone."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height, bits, colour = struct.unpack(">IIBB", data[16:26])
    assert (bits, colour) == (16, 0)
    chunks, offset = b"", 8
    while offset < len(data):
        (length,) = struct.unpack(">I", data[offset : offset + 4])
        if data[offset + 4 : offset + 8] == b"IDAT":
            chunks += data[offset + 8 : offset + 8 + length]
        offset += 12 + length
    rows = np.frombuffer(zlib.decompress(chunks), np.uint8).reshape(height, 1 + 2 * width)
    return rows[:, 1:].copy().view(">u2").astype(np.float64)


def test_pixel_rays_put_the_centre_ray_on_the_axis_one_focal_length_per_pixel() -> None:
    focal = focal_length_px(3, 90.0)
    assert focal == pytest.approx(1.5)  # (height / 2) / tan(fovy / 2)
    rays = pixel_rays(3, 3, focal)  # MuJoCo's camera frame: x right, y up, along -z
    assert rays[1, 1] == pytest.approx([0.0, 0.0, -1.0])
    # the pixel right of the centre is one pixel off-axis: x = z / f; the one above, y = z / f
    assert rays[1, 2] == pytest.approx([1.0 / 1.5, 0.0, -1.0])
    assert rays[0, 1] == pytest.approx([0.0, 1.0 / 1.5, -1.0])
