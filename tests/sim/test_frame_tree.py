"""Tests for frame_tree.py: the TF frames of every robot's default native scene, in process.

After a reset and a few control steps towards random joint targets, the transforms the tree
gives (parent → child, :meth:`FrameSample.relative`), chained from the world by frame
name, land every body frame on MuJoCo's ``xpos``/``xquat``, every camera's optical frame on
the camera turned half a turn about x (REP 103: z forward, y down), every site's frame on
``site_xpos``/``site_xmat``. Static transforms hold still while the robot moves; a mobile
base hangs from an odometry frame fixed where it was at the reset; a base frame named after
another body of the model is refused by name.
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import open_robot
from openral_core.loader import load_scene
from openral_core.models import Backend, LimitedJoint, SiteSensor
from openral_mujoco.errors import HalError
from openral_mujoco.robot_tree import BaseKind
from openral_sim.frame_tree import Frame, FrameTree, camera_link
from openral_sim.native_scene import NativeScene
from openral_sim.robot_description import (
    robot_description,
    scene_robot_description,
    sensor_frames,
)
from openral_sim.scene import build_scene, build_sim_env_from_yaml
from openral_sim.scene_cameras import camera_sensors

from tests.conftest import ROBOTS, ManifestWriter

POSITION_TOLERANCE_M = 1e-6
ANGLE_TOLERANCE_RAD = 1e-6
STILL = 1e-9
"""Largest change [m or rad] of a transform that holds still (rounding only)."""
STEPS = 5
"""Control steps towards each set of random targets."""
TARGET_SPREAD_RAD = 0.3
"""Largest offset of a random target from the held pose [rad or m], inside the limits."""
OPTICAL = np.diag([1.0, -1.0, -1.0])
"""A MuJoCo camera frame (looks along -z, y up) → its REP 103 optical frame (z forward)."""
CAMERA_AXES = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])
"""A MuJoCo camera frame → its camera link (REP 103 body axes: x forward, y left, z up)."""


def _default_scenes() -> dict[str, Path]:
    """The first native scene of every robot (the mobile Panda's is its room)."""
    scenes: dict[str, Path] = {}
    for path in sorted(ROBOTS.glob("*/scenes/*.yaml")):
        robot = path.parent.parent.name
        if robot not in scenes and load_scene(path).scene.backend is Backend.native:
            scenes[robot] = path
    return scenes


SCENES = _default_scenes()
MOBILE = "panda_mobile"


@functools.cache
def _scene(robot_id: str) -> NativeScene:
    scene = build_sim_env_from_yaml(SCENES[robot_id])
    assert isinstance(scene, NativeScene), f"{SCENES[robot_id]} is not a native scene"
    scene.render_observations = False
    return scene


# -- poses -----------------------------------------------------------------------------------


def _matrix(position: np.ndarray, quat: np.ndarray) -> np.ndarray:
    rotation = np.empty(9)
    mujoco.mju_quat2Mat(rotation, np.asarray(quat, dtype=np.float64))
    transform = np.eye(4)
    transform[:3, :3] = rotation.reshape(3, 3)
    transform[:3, 3] = position
    return transform


def _from_rotation(position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    transform = np.eye(4)
    transform[:3, :3] = np.asarray(rotation).reshape(3, 3)
    transform[:3, 3] = position
    return transform


def _errors(actual: np.ndarray, expected: np.ndarray) -> tuple[float, float]:
    """(distance [m], angle [rad]) between two poses (4x4), accurate near zero."""
    turn = actual[:3, :3].T @ expected[:3, :3]
    sine = np.linalg.norm(
        [turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0], turn[1, 0] - turn[0, 1]]
    )
    angle = math.atan2(sine / 2, (np.trace(turn) - 1) / 2)
    return float(np.linalg.norm(actual[:3, 3] - expected[:3, 3])), angle


def _still(actual: np.ndarray, expected: np.ndarray) -> bool:
    """The two poses are one to rounding."""
    return max(_errors(actual, expected)) <= STILL


def _relative(tree: FrameTree, data: mujoco.MjData) -> dict[str, np.ndarray]:
    """Every frame but the world: its transform in its parent (4x4), by name."""
    rows = np.arange(1, len(tree.frames), dtype=np.intp)
    positions, quats = tree.sample(data).relative(tree, rows)
    return {tree.frames[row].name: _matrix(positions[i], quats[i]) for i, row in enumerate(rows)}


def _world_poses(tree: FrameTree, data: mujoco.MjData) -> dict[str, np.ndarray]:
    """Every frame's world pose, chained from the world through the parents it names."""
    relative = _relative(tree, data)
    world: dict[str, np.ndarray] = {tree.names.world: np.eye(4)}
    for frame in tree.frames[1:]:
        assert frame.parent in world, (
            f"{frame.name}: parent {frame.parent!r} is not laid out before it"
        )
        world[frame.name] = world[frame.parent] @ relative[frame.name]
    return world


# -- driving ---------------------------------------------------------------------------------


def _move(scene: NativeScene, rng: np.random.Generator, steps: int = STEPS) -> None:
    """``steps`` control steps towards random arm targets near the held pose, inside the
    manifest's limits (grippers held)."""
    action = scene.hold_action()
    joints = {joint.name: joint for joint in scene.robot.description.joints}
    for slot in scene.addresses.arm_slots:
        joint = joints[scene.action_names[slot]]
        low, high = -math.inf, math.inf
        if isinstance(joint, LimitedJoint):
            low, high = joint.position_limits
        offset = rng.uniform(-TARGET_SPREAD_RAD, TARGET_SPREAD_RAD)
        action[slot] = float(np.clip(action[slot] + offset, low, high))
    for _ in range(steps):
        scene.step(action)


def _moved(robot_id: str, seed: int = 0) -> NativeScene:
    scene = _scene(robot_id)
    scene.reset(seed)
    _move(scene, np.random.default_rng(zlib.crc32(robot_id.encode()) + seed))
    return scene


# -- every robot -----------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id", sorted(SCENES))
def test_chained_transforms_land_on_mujocos_poses(robot_id: str) -> None:
    scene = _moved(robot_id)
    tree, data, model = scene.frame_tree, scene.data, scene.model
    world = _world_poses(tree, data)
    root = _matrix(data.xpos[tree.tree.root], data.xquat[tree.tree.root])
    offset = np.eye(4)  # the root body in the base frame: a mobile base's is off its axis
    if tree.tree.kind is BaseKind.MOBILE and scene.base is not None:
        offset[:3, 3] = scene.base.root_in_base_frame
    expected: dict[str, np.ndarray] = {tree.names.base: root @ np.linalg.inv(offset)}
    for link in tree.tree.links:
        if link.body >= 0:
            expected[link.name] = _matrix(data.xpos[link.body], data.xquat[link.body])
        elif link.parent is not None:  # an extra link (the Panda's flange): fixed to its parent
            expected[link.name] = expected[link.parent] @ _matrix(
                np.array(link.position), np.array(link.quat)
            )
    description = scene.robot.description
    cameras = camera_sensors(scene.scene, description)
    for sensor in description.sensors:
        if sensor.name in cameras:
            camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, cameras[sensor.name])
            rotation = data.cam_xmat[camera].reshape(3, 3) @ OPTICAL
            expected[sensor.frame_id] = _from_rotation(data.cam_xpos[camera], rotation)
            link = camera_link(sensor.frame_id)  # x forward (-z of MuJoCo's camera), z up (y)
            if link is not None and link in tree.names_of_frames:
                body_axes = data.cam_xmat[camera].reshape(3, 3) @ CAMERA_AXES
                expected[link] = _from_rotation(data.cam_xpos[camera], body_axes)
        elif isinstance(sensor, SiteSensor):
            site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, sensor.site)
            expected[sensor.frame_id] = _from_rotation(data.site_xpos[site], data.site_xmat[site])
    wrong = {}
    for name, pose in expected.items():
        distance, angle = _errors(world[name], pose)
        if distance > POSITION_TOLERANCE_M or angle > ANGLE_TOLERANCE_RAD:
            wrong[name] = (distance, angle)
    assert not wrong, f"frames off MuJoCo's poses (m, rad): {wrong}"
    unchecked = set(tree.names_of_frames) - set(expected)
    assert unchecked <= {tree.names.world, tree.names.odom}, unchecked


@pytest.mark.parametrize("robot_id", sorted(SCENES))
def test_frame_names_are_unique_and_every_served_sensor_has_its_frame(robot_id: str) -> None:
    scene = _scene(robot_id)
    tree = scene.frame_tree
    names = tree.names_of_frames
    assert len(set(names)) == len(names)
    assert names[0] == tree.names.world and tree.frames[0].parent == ""
    served = set(scene.scene.scene.cameras)
    for sensor in scene.robot.description.sensors:
        if sensor.name in served or isinstance(sensor, SiteSensor):
            assert sensor.frame_id in names, f"sensor {sensor.name}: no frame {sensor.frame_id!r}"
    laid_out: set[str] = set()
    for frame in tree.frames:  # parents before children
        assert frame.parent == "" or frame.parent in laid_out, frame
        laid_out.add(frame.name)


@pytest.mark.parametrize("robot_id", sorted(SCENES))
def test_only_dynamic_transforms_change_as_the_robot_moves(robot_id: str) -> None:
    scene = _moved(robot_id)
    tree = scene.frame_tree
    before = _relative(tree, scene.data)
    _move(scene, np.random.default_rng(zlib.crc32(robot_id.encode()) + 1))
    after = _relative(tree, scene.data)
    changed = set()
    for name, pose in before.items():
        if not _still(after[name], pose):
            changed.add(name)
    static = {tree.frames[row].name for row in tree.static}
    dynamic = {tree.frames[row].name for row in tree.dynamic}
    assert static | dynamic == set(before) and not static & dynamic
    assert not changed & static, f"static transforms moved: {sorted(changed & static)}"
    assert changed, "nothing moved"


# -- a mobile base ---------------------------------------------------------------------------


def test_a_mobile_base_hangs_from_an_odometry_frame_fixed_at_the_reset() -> None:
    scene = _scene(MOBILE)
    scene.reset(0)
    tree, names = scene.frame_tree, scene.frame_tree.names
    assert names.odom is not None and scene.base is not None
    assert tree.frames[1] == Frame(names.odom, names.world, static=True)
    assert tree.frames[2] == Frame(names.base, names.odom, static=False)
    at_reset = _relative(tree, scene.data)
    assert _still(at_reset[names.base], np.eye(4))  # the odometry frame is the base frame now
    x, y, heading = scene.base.origin
    odom = at_reset[names.odom]
    assert np.allclose(odom[:2, 3], (x, y), atol=STILL)
    assert math.atan2(odom[1, 0], odom[0, 0]) == pytest.approx(heading, abs=STILL)
    action = scene.hold_action()
    for _ in range(10):  # 0.5 s forward and turning
        scene.base.command(0.3, 0.0, 0.3)
        scene.step(action)
    driven = _relative(tree, scene.data)
    assert _still(driven[names.odom], odom)
    odometry = scene.base.odometry()
    assert odometry.x_m > 0.05 and odometry.yaw_rad > 0.05  # it moved
    expected = np.eye(4)
    c, s = math.cos(odometry.yaw_rad), math.sin(odometry.yaw_rad)
    expected[:2, :2] = [[c, -s], [s, c]]
    expected[:2, 3] = odometry.x_m, odometry.y_m
    distance, angle = _errors(driven[names.base], expected)
    assert distance < POSITION_TOLERANCE_M and angle < ANGLE_TOLERANCE_RAD, (
        f"odom → {names.base} is {distance:.3g} m, {angle:.3g} rad off the base's odometry "
        f"at {odometry.sim_time_s:.3f} s"
    )


# -- a base frame named after a body ---------------------------------------------------------


def test_a_base_frame_named_after_a_body_of_the_model_is_refused(
    write_manifest: ManifestWriter,
) -> None:
    manifest = write_manifest(  # the model's non-root body base_link, not renamed
        ("  links: {base: base_link, base_link: base_link_inertia}\n", ""),
        ("  joints: {base_link_inertia: base_link-base_link_inertia}\n", ""),
        base=ROBOTS / "ur10e" / "robot.yaml",
        folder="ur10e",
    )
    scene = build_scene(
        load_scene(ROBOTS / "ur10e" / "scenes" / "tabletop.yaml"),
        open_robot(manifest),
        render_observations=False,
    )
    assert isinstance(scene, NativeScene)
    with pytest.raises(HalError, match="'base_link'") as refused:
        _ = scene.frame_tree
    assert "base frame" in str(refused.value)


# -- the URDF a running scene publishes --------------------------------------------------------


@pytest.mark.parametrize("robot_id", sorted(SCENES))
def test_a_scene_publishes_the_urdf_of_the_robot_alone(robot_id: str) -> None:
    """What the graph reads from its scene's model is what ``openral robot urdf`` writes, and
    then the sensors' frames fixed on the robot, as empty links on fixed joints."""
    scene = _scene(robot_id)
    published = scene_robot_description(scene.frame_tree, scene.robot.name)
    alone = robot_description(scene.robot)
    closing = "</robot>\n"
    assert published.startswith(alone[: -len(closing)]) and published.endswith(closing)
    added = ET.fromstring(f"<robot>{published[len(alone) - len(closing) : -len(closing)]}</robot>")
    frames = {f.name for f in sensor_frames(scene.frame_tree)}
    assert {link.get("name") for link in added.iter("link")} == frames
    assert {joint.get("type") for joint in added.iter("joint")} <= {"fixed"}
