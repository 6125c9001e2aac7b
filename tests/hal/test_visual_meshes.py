"""Tests for visual_meshes.py and robot_edits.py: ``sim.visual_mesh_faces`` simplifies the
heavy meshes that only show, and changes nothing else: not the physics, hardly the picture."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import open_robot, open_robot_by_id
from openral_core.errors import ManifestError
from openral_core.loaded import LoadedRobot
from openral_core.models import RobotDescription
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import compile_robot_model
from openral_mujoco.robot_edits import edit_robot_spec, robot_cache_kind
from openral_mujoco.visual_meshes import INERTIAL

PANDA = open_robot_by_id("franka_panda")
FACES = 1500
"""franka_panda's sim.visual_mesh_faces."""


def _without_budget(description: RobotDescription) -> RobotDescription:
    assert description.sim is not None
    sim = description.sim.model_copy(update={"visual_mesh_faces": None})
    return description.model_copy(update={"sim": sim})


def _panda_models() -> tuple[mujoco.MjModel, mujoco.MjModel]:
    """(the Panda's model as openral compiles it, the same without the mesh budget)."""
    description = PANDA.description
    assert description.sim is not None and description.sim.visual_mesh_faces == FACES
    path = robot_model_file(description, PANDA.folder)
    plain = edit_robot_spec(mujoco.MjSpec.from_file(str(path)), _without_budget(description))
    return compile_robot_model(description, path), plain.compile()


def _visual_only(model: mujoco.MjModel) -> set[int]:
    meshes = {}
    for g in range(model.ngeom):
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            shown = model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0
            meshes[int(model.geom_dataid[g])] = (
                meshes.get(int(model.geom_dataid[g]), True) and shown
            )
    return {mesh for mesh, shown in meshes.items() if shown}


def _vertices(model: mujoco.MjModel, mesh: int) -> np.ndarray:
    start = model.mesh_vertadr[mesh]
    return np.asarray(model.mesh_vert[start : start + model.mesh_vertnum[mesh]])


def test_heavy_visual_meshes_are_simplified_and_nothing_else_is() -> None:
    edited, plain = _panda_models()
    assert edited.nmesh == plain.nmesh
    visual = _visual_only(plain)
    simplified = 0
    for mesh in range(plain.nmesh):
        before, after = int(plain.mesh_facenum[mesh]), int(edited.mesh_facenum[mesh])
        if mesh in visual and before > FACES:
            assert FACES / 2 <= after <= FACES, (plain.mesh(mesh).name, before, after)
            simplified += 1
        else:
            assert after == before, plain.mesh(mesh).name
            assert np.array_equal(_vertices(edited, mesh), _vertices(plain, mesh))
    print(f"{simplified} meshes simplified; faces {plain.nmeshface} -> {edited.nmeshface}")
    assert simplified >= 10 and edited.nmeshface < plain.nmeshface / 3
    for key in (*INERTIAL, "body_pos", "body_quat", "jnt_range", "actuator_gainprm"):
        assert np.array_equal(getattr(edited, key), getattr(plain, key)), key
    colliding = [
        g for g in range(plain.ngeom) if plain.geom_contype[g] or plain.geom_conaffinity[g]
    ]
    for key in ("geom_size", "geom_pos", "geom_quat", "geom_dataid"):
        assert np.array_equal(getattr(edited, key)[colliding], getattr(plain, key)[colliding])


def test_the_physics_is_the_same_bit_for_bit() -> None:
    edited, plain = _panda_models()
    datas = [mujoco.MjData(m) for m in (edited, plain)]
    for data, model in zip(datas, (edited, plain), strict=True):
        mujoco.mj_resetDataKeyframe(model, data, 0)
    low, high = plain.actuator_ctrlrange.T
    for step in range(600):
        ctrl = low + (high - low) * (0.5 + 0.4 * np.sin(0.01 * step + np.arange(plain.nu)))
        for data, model in zip(datas, (edited, plain), strict=True):
            data.ctrl[:] = ctrl
            mujoco.mj_step(model, data)
    assert np.array_equal(datas[0].qpos, datas[1].qpos)
    assert np.array_equal(datas[0].qvel, datas[1].qvel)


def _picture(model: mujoco.MjModel) -> np.ndarray:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    camera = mujoco.MjvCamera()
    camera.lookat[:], camera.distance, camera.azimuth, camera.elevation = (
        (0.3, 0, 0.4),
        1.6,
        150,
        -20,
    )
    with mujoco.Renderer(model, 128, 128) as renderer:
        renderer.update_scene(data, camera)
        return renderer.render().astype(np.float64)


def test_the_picture_hardly_changes() -> None:
    edited, plain = (_picture(model) for model in _panda_models())
    difference = np.abs(edited - plain)
    off = (difference.max(axis=-1) > 20).mean()
    print(
        f"mean difference {difference.mean():.2f} of 255; {100 * off:.2f} % of pixels off by > 20"
    )
    assert plain.std() > 10  # the arm is in the picture
    assert difference.mean() < 2.0 and off < 0.03


BALL = """
<mujoco>
  <asset><mesh name="ball" vertex="VERTICES" face="FACES"/></asset>
  <worldbody>
    <body name="arm" pos="0 0 0.5">
      <joint name="shoulder" axis="0 1 0" range="-2 2"/>
      <geom type="mesh" mesh="ball" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <actuator><position joint="shoulder" kp="10" ctrlrange="-2 2"/></actuator>
</mujoco>
"""
"""A body that takes its inertia from a mesh that collides with nothing."""


def _sphere(rings: int = 16, segments: int = 24) -> tuple[str, str]:
    """A UV sphere of radius 0.1 m as MJCF vertex and face lists."""
    vertices = [(0.0, 0.0, 0.1), (0.0, 0.0, -0.1)]
    for i in range(1, rings):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            x, y, z = np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)
            vertices.append((0.1 * x, 0.1 * y, 0.1 * z))
    ring = lambda i, j: 2 + (i - 1) * segments + j % segments  # noqa: E731
    faces = [(0, ring(1, j), ring(1, j + 1)) for j in range(segments)]
    faces += [(1, ring(rings - 1, j + 1), ring(rings - 1, j)) for j in range(segments)]
    for i in range(1, rings - 1):
        for j in range(segments):
            faces.append((ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)))
            faces.append((ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)))
    return " ".join(f"{c:.6f}" for v in vertices for c in v), " ".join(map(str, np.ravel(faces)))


def _ball_robot(tmp_path: Path) -> LoadedRobot:
    folder = tmp_path / "ball_arm"
    folder.mkdir()
    vertices, faces = _sphere()
    (folder / "arm.xml").write_text(BALL.replace("VERTICES", vertices).replace("FACES", faces))
    (folder / "robot.yaml").write_text(
        'schema_version: "0.1"\nname: ball_arm\ndisplay_name: Ball arm\nbase: fixed\n'
        "joints:\n  - {name: shoulder, type: revolute, position_limits: [-2.0, 2.0], "
        "velocity_limit: 2.0, effort_limit: 20.0}\nsensors: []\n"
        "sim:\n  mjcf_uri: file:arm.xml\n  visual_mesh_faces: 100\n"
    )
    return open_robot(folder / "robot.yaml")


def test_a_mesh_a_body_takes_its_inertia_from_is_refused_at_the_field(tmp_path: Path) -> None:
    robot = _ball_robot(tmp_path)
    with pytest.raises(ManifestError) as info:
        compile_robot_model(robot.description, robot_model_file(robot.description, robot.folder))
    message = str(info.value)
    assert message.startswith(
        f"{tmp_path / 'ball_arm' / 'robot.yaml'}:10:3: sim.visual_mesh_faces: "
    ), message
    assert "visual_mesh_faces" in message and "changes body_mass" in message
    assert len(message.splitlines()) == 1


def test_the_cache_never_serves_a_model_with_other_edits() -> None:
    description = PANDA.description
    assert robot_cache_kind(description) == f"robot+gravcomp-1+faces-{FACES}-1"
    assert robot_cache_kind(_without_budget(description)) == "robot+gravcomp-1"
