"""Tests for robot_description.py (and the URDF and mesh files it is made of): every robot's
URDF parses, names its joints as the manifest does, and moves as MuJoCo moves it."""

from __future__ import annotations

import functools
import io
import math
import re
import shutil
import sys
import tempfile
import zlib
from dataclasses import dataclass, replace
from pathlib import Path
from urllib.parse import unquote, urlparse

import mujoco
import numpy as np
import pytest
import yourdfpy
from openral_cli.main import app
from openral_core import open_robot, open_robot_by_id
from openral_core.loaded import LoadedRobot
from openral_core.models import LimitedJoint
from openral_core.registry import robot_ids
from openral_mujoco.mesh_export import (
    MeshExporter,
    MeshExportFailed,
    capsule_triangles,
    ellipsoid_triangles,
    mesh_folder,
)
from openral_mujoco.model_cache import CACHE_ENV
from openral_mujoco.robot_tree import RobotTree, TreeUnsupported, robot_tree
from openral_mujoco.urdf import rpy, urdf_text
from openral_sim.robot_description import robot_description
from openral_sim.scene_base import robot_alone
from typer.testing import CliRunner

from tests.conftest import ROBOTS

CONFIGURATIONS = 20
"""Random joint configurations compared per robot."""
POSITION_TOLERANCE_M = 1e-3
ANGLE_TOLERANCE_RAD = 1e-3
RIZON = ROBOTS / "rizon4"
runner = CliRunner()


@dataclass(frozen=True)
class Described:
    """A robot, its model alone, its tree and its URDF (text and parsed)."""

    robot: LoadedRobot
    model: mujoco.MjModel
    tree: RobotTree
    text: str
    urdf: yourdfpy.URDF


def _describe(robot: LoadedRobot) -> Described:
    alone = robot_alone(robot)
    tree = robot_tree(alone.model, robot.description, robot.tables, alone.addresses)
    text = robot_description(robot)
    urdf = yourdfpy.URDF.load(io.StringIO(text), load_meshes=False)
    return Described(robot, alone.model, tree, text, urdf)


@functools.cache
def _described(robot_id: str) -> Described:
    return _describe(open_robot_by_id(robot_id))


# -- every robot -----------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id", robot_ids())
def test_urdf_parses_with_the_trees_root_and_the_manifests_joints(robot_id: str) -> None:
    described = _described(robot_id)
    urdf, tree = described.urdf, described.tree
    assert urdf.validate(), robot_id
    assert urdf.base_link == tree.base
    assert {link.name for link in tree.links} <= set(urdf.link_map)
    for joint in described.robot.description.joints:
        stated = urdf.joint_map[joint.name]
        assert stated.type == joint.type
        assert stated.limit.velocity == joint.velocity_limit
        assert stated.limit.effort == joint.effort_limit
        if isinstance(joint, LimitedJoint):
            assert (stated.limit.lower, stated.limit.upper) == tuple(joint.position_limits)


@pytest.mark.parametrize("robot_id", robot_ids())
def test_every_mesh_file_is_a_binary_stl_of_its_geom(robot_id: str) -> None:
    described = _described(robot_id)
    model, exporter = described.model, MeshExporter(described.model)
    expected: dict[Path, int] = {}
    for link in described.tree.links:
        if link.body < 0:
            continue
        first = int(model.body_geomadr[link.body])
        for geom in range(first, first + int(model.body_geomnum[link.body])):
            expected.update(_expected_triangles(model, geom, exporter))
    named = {
        Path(unquote(urlparse(m).path)) for m in re.findall(r'filename="([^"]+)"', described.text)
    }
    assert named == set(expected)
    for path, triangles in expected.items():
        data = path.read_bytes()
        assert int.from_bytes(data[80:84], "little") == triangles, path
        assert len(data) == 84 + 50 * triangles, path


def _expected_triangles(
    model: mujoco.MjModel, geom: int, exporter: MeshExporter
) -> dict[Path, int]:
    kind, size = int(model.geom_type[geom]), model.geom_size[geom]
    if kind == mujoco.mjtGeom.mjGEOM_MESH:
        count = int(model.mesh_facenum[model.geom_dataid[geom]])
    elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        count = len(capsule_triangles(float(size[0]), float(size[1])))
    elif kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        count = len(ellipsoid_triangles((float(size[0]), float(size[1]), float(size[2]))))
    else:
        return {}
    shown = (
        int(model.geom_group[geom]) <= 2 or model.geom_contype[geom] or model.geom_conaffinity[geom]
    )
    return {exporter.geom_file(geom): count} if shown else {}


@pytest.mark.parametrize("robot_id", robot_ids())
def test_urdf_kinematics_match_mujoco(robot_id: str) -> None:
    _assert_same_kinematics(_described(robot_id), zlib.crc32(robot_id.encode()))


def _assert_same_kinematics(described: Described, seed: int) -> None:
    """At random configurations, every body's link pose relative to the base link is the
    same in yourdfpy as in MuJoCo."""
    model, tree, urdf = described.model, described.tree, described.urdf
    rng = np.random.default_rng(seed)
    data = mujoco.MjData(model)
    root = next(link for link in tree.links if link.body == tree.root)
    for _ in range(CONFIGURATIONS):
        urdf.update_cfg(_random_configuration(tree, rng, data))
        mujoco.mj_kinematics(model, data)
        # the root body's link hangs rigidly from the base link at its origin
        base = _pose(data, tree.root) @ np.linalg.inv(_transform(root.position, root.quat))
        for link in tree.links:
            if link.body < 0:
                continue
            expected = np.linalg.inv(base) @ _pose(data, link.body)
            actual = urdf.get_transform(link.name, tree.base)
            assert np.linalg.norm(actual[:3, 3] - expected[:3, 3]) < POSITION_TOLERANCE_M, link.name
            turn = actual[:3, :3].T @ expected[:3, :3]
            angle = math.acos(min(1.0, max(-1.0, (np.trace(turn) - 1) / 2)))
            assert angle < ANGLE_TOLERANCE_RAD, link.name


def _random_configuration(
    tree: RobotTree, rng: np.random.Generator, data: mujoco.MjData
) -> dict[str, float]:
    """Set ``data.qpos``: each independent joint drawn inside its limits (continuous: ±π),
    each mimic joint by its rule, every other joint as the tree was read; the independent
    joints' values by name."""
    data.qpos[:] = _zero_qpos(data.model)
    values: dict[str, float] = {}
    for joint in tree.joints:
        if joint.mimic is None:
            continuous = joint.kind == "continuous"
            low, high = (-math.pi, math.pi) if continuous else (joint.lower, joint.upper)
            values[joint.name] = data.qpos[joint.qpos] = float(rng.uniform(low, high))
    for joint in tree.joints:
        if joint.mimic is not None:
            mimic = joint.mimic
            data.qpos[joint.qpos] = mimic.multiplier * values[mimic.joint] + mimic.offset
    return values


def _zero_qpos(model: mujoco.MjModel) -> np.ndarray:
    """qpos0 with every hinge and slide at 0 (the pose the tree was read at)."""
    qpos = model.qpos0.copy()
    for joint in range(model.njnt):
        if model.jnt_type[joint] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            qpos[model.jnt_qposadr[joint]] = 0.0
    return qpos


def _pose(data: mujoco.MjData, body: int) -> np.ndarray:
    return _transform(data.xpos[body], data.xquat[body])


def _transform(position: object, quat: object) -> np.ndarray:
    matrix = np.empty(9)
    mujoco.mju_quat2Mat(matrix, np.asarray(quat, dtype=np.float64))
    transform = np.eye(4)
    transform[:3, :3] = matrix.reshape(3, 3)
    transform[:3, 3] = np.asarray(position, dtype=np.float64)
    return transform


# -- an offset axis, an ellipsoid, a tree with no URDF -----------------------------------------


def _rizon_copy(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    """A copy of robots/rizon4 with ``edits`` (old, new) made to its MJCF; its manifest."""
    folder = tmp_path / "robots" / "rizon4"
    shutil.copytree(RIZON, folder)
    model = folder / "mjcf" / "rizon4.xml"
    text = model.read_text(encoding="utf-8")
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    model.write_text(text, encoding="utf-8")
    return folder / "robot.yaml"


def test_an_axis_off_the_link_origin_and_an_ellipsoid_move_as_in_mujoco(tmp_path: Path) -> None:
    manifest = _rizon_copy(
        tmp_path,
        (
            '<joint name="joint4" axis="0 1 0"',
            '<joint name="joint4" pos="0.03 -0.02 0.05" axis="0 1 0"',
        ),
        (
            '<site name="flange"',
            '<geom type="ellipsoid" size="0.02 0.03 0.04" pos="0 0 0.06" '
            'euler="0.3 1.5707963 0.2"/><site name="flange"',
        ),
    )
    described = _describe(open_robot(manifest))
    assert '<link name="link4_axis" />' in described.text
    assert 'name="link4_fixed"' in described.text
    assert described.text.count("<mesh ") == 2 * (6 + 1)  # 6 capsules, 1 ellipsoid: seen, touched
    _assert_same_kinematics(described, seed=4)


def test_a_tree_with_no_urdf_form_is_one_line_from_the_cli(tmp_path: Path) -> None:
    manifest = _rizon_copy(
        tmp_path,
        (
            '<site name="flange"',
            '<body name="tip"><joint name="tip" type="ball"/>'
            '<geom type="sphere" size="0.01"/></body><site name="flange"',
        ),
        ('qpos="0 0 0 1.57 0 0 0"', 'qpos="0 0 0 1.57 0 0 0 1 0 0 0"'),
    )
    result = runner.invoke(app, ["robot", "urdf", str(manifest)])
    assert result.exit_code == 1
    assert (
        result.output
        == "error: robot 'rizon4' has no URDF: body 'tip' has a ball joint; a URDF has none\n"
    )


def test_an_unknown_robot_is_one_line_from_the_cli(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from openral_cli import main

    monkeypatch.setattr(sys, "argv", ["openral", "robot", "urdf", "no_such_robot"])
    with pytest.raises(SystemExit) as exit_:
        main.run()
    assert exit_.value.code == 1
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: unknown robot 'no_such_robot'")


# -- determinism, the mesh cache, the CLI -----------------------------------------------------


def test_the_text_is_deterministic_and_a_second_call_writes_no_mesh() -> None:
    robot = open_robot_by_id("franka_panda")
    first = robot_description(robot)
    folder = mesh_folder()
    before = {path: path.stat().st_mtime_ns for path in folder.iterdir()}
    assert robot_description(robot) == first
    assert {path: path.stat().st_mtime_ns for path in folder.iterdir()} == before


def test_the_cli_writes_what_robot_description_returns(tmp_path: Path) -> None:
    expected = _described("so100").text
    target = tmp_path / "so100.urdf"
    result = runner.invoke(app, ["robot", "urdf", "so100", "--out", str(target)])
    assert result.exit_code == 0, result.output
    assert target.read_text(encoding="utf-8") == expected
    assert f"wrote the URDF of so100 to {target}" in result.output
    printed = runner.invoke(app, ["robot", "urdf", "so100"])
    assert printed.exit_code == 0 and printed.stdout == expected


def test_two_joints_of_one_name_are_refused() -> None:
    described = _described("rizon4")
    tree = described.tree
    links = list(tree.links)
    index = next(i for i, link in enumerate(links) if link.name == "link1")
    joint = links[index].joint
    assert joint is not None
    links[index] = replace(links[index], joint=replace(joint, name="base_fixed"))
    clashing = replace(tree, links=tuple(links))
    with pytest.raises(TreeUnsupported, match="two joints named 'base_fixed'"):
        urdf_text(clashing, described.model, "rizon4")


def test_meshes_go_to_the_temporary_directory_when_the_model_cache_is_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv(CACHE_ENV, "off")
    assert mesh_folder() == Path(tempfile.gettempdir()) / "openral-meshes"


def test_an_unwritable_mesh_folder_is_one_clear_error(tmp_path: Path) -> None:
    model = _described("h1").model
    capsule = int(np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_CAPSULE)[0])
    (tmp_path / "file").write_text("")
    exporter = MeshExporter(model, folder=tmp_path / "file" / "meshes")
    with pytest.raises(MeshExportFailed, match=r"cannot write mesh files to .*file/meshes: "):
        exporter.geom_file(capsule)


def test_rpy_states_every_rotation_exactly_even_at_gimbal_lock() -> None:
    rng = np.random.default_rng(7)
    quats = [q / np.linalg.norm(q) for q in rng.normal(size=(200, 4))]
    half = math.sqrt(0.5)
    quats += [np.array([half, 0.0, s * half, 0.0]) for s in (1.0, -1.0)]  # pitch ±90°
    quats += [np.array([0.5, 0.5, 0.5, 0.5]), np.array([0.5, -0.5, 0.5, -0.5])]
    for quat in quats:
        roll, pitch, yaw = rpy(tuple(quat))
        rotation = _rotation("z", yaw) @ _rotation("y", pitch) @ _rotation("x", roll)
        assert np.allclose(rotation, _transform((0, 0, 0), quat)[:3, :3], atol=1e-12), quat


def _rotation(axis: str, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    rotation = np.eye(3)
    rotation[i, i] = rotation[j, j] = c
    rotation[j, i], rotation[i, j] = s, -s
    return rotation
