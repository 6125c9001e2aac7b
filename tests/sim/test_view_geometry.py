"""Tests for view_geometry.py: what the browser view draws of a scene's model.

On the franka tabletop and the G1 (a floating base) after random joint targets: chaining
the parent-relative poses :func:`relative_poses` gives from the world down each entity path
lands every body on MuJoCo's ``xpos``/``xquat``; paths follow the kinematic tree and are
unique; only geoms of groups 0-2 that are not fully transparent are drawn, meshes with
their vertices and faces; bodies fixed to their parent are not in ``moving``.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from openral_sim.scene import build_sim_env_from_yaml
from openral_sim.view_geometry import GeomShape, body_tree, relative_poses, visible_geoms

from tests.conftest import ROBOTS

SCENES = {
    "franka_tabletop": ROBOTS / "franka_panda/scenes/tabletop.yaml",
    "g1": ROBOTS / "g1/scenes/tabletop.yaml",
}


@pytest.fixture(scope="module", params=sorted(SCENES))
def scene(request: pytest.FixtureRequest):  # type: ignore[no-untyped-def]
    path = SCENES[request.param]
    if not path.exists():
        pytest.fail(f"{path} is missing")
    env = build_sim_env_from_yaml(path)
    env.reset(seed=0)
    yield env
    env.close()


def _quat_xyzw_to_wxyz(q: np.ndarray) -> np.ndarray:
    return np.concatenate([q[-1:], q[:-1]])


def test_chained_relative_poses_land_every_body_on_mujoco(scene) -> None:  # type: ignore[no-untyped-def]
    model, data = scene.mujoco_handles()
    tree = body_tree(model)
    rng = np.random.default_rng(3)
    for _ in range(3):
        data.qpos[:] = model.qpos0 + 0.3 * rng.standard_normal(model.nq)
        mujoco.mj_normalizeQuat(model, data.qpos)
        mujoco.mj_kinematics(model, data)
        every = tuple(range(1, model.nbody))
        translations, quats = relative_poses(data, tree, every)
        world_pos, world_quat = {0: np.zeros(3)}, {0: np.array([1.0, 0, 0, 0])}
        for body, t, q in zip(every, translations, quats, strict=True):
            parent = int(model.body_parentid[body])
            rotated = np.empty(3)
            mujoco.mju_rotVecQuat(rotated, t, world_quat[parent])
            world_pos[body] = world_pos[parent] + rotated
            composed = np.empty(4)
            mujoco.mju_mulQuat(composed, world_quat[parent], _quat_xyzw_to_wxyz(q))
            world_quat[body] = composed
            assert np.allclose(world_pos[body], data.xpos[body], atol=1e-9)
            same = min(
                np.abs(composed - data.xquat[body]).max(), np.abs(composed + data.xquat[body]).max()
            )
            assert same < 1e-9


def test_paths_follow_the_tree_and_are_unique(scene) -> None:  # type: ignore[no-untyped-def]
    model, _ = scene.mujoco_handles()
    tree = body_tree(model)
    assert len(set(tree.paths)) == model.nbody
    for body in range(1, model.nbody):
        parent = tree.paths[int(model.body_parentid[body])]
        assert tree.paths[body].startswith(parent + "/")
        assert "/" not in tree.paths[body][len(parent) + 1 :]
    fixed = [
        b for b in range(1, model.nbody) if model.body_jntnum[b] == 0 and model.body_mocapid[b] < 0
    ]
    assert not set(fixed) & set(tree.moving)
    assert all(model.body_jntnum[b] > 0 or model.body_mocapid[b] >= 0 for b in tree.moving)


def test_only_visible_geoms_are_drawn(scene) -> None:  # type: ignore[no-untyped-def]
    model, _ = scene.mujoco_handles()
    tree = body_tree(model)
    geoms = visible_geoms(model, tree)
    drawn = {g.path for g in geoms}
    assert len(drawn) == len(geoms)
    expected = sum(
        1
        for g in range(model.ngeom)
        if model.geom_group[g] < 3
        and model.geom_type[g] in {s.value for s in GeomShape}
        and (
            model.mat_rgba[model.geom_matid[g]] if model.geom_matid[g] >= 0 else model.geom_rgba[g]
        )[3]
        > 0
    )
    assert len(geoms) == expected > 0
    meshes = [g for g in geoms if g.shape == GeomShape.MESH]
    assert meshes, "the robot's links are meshes"
    for mesh in meshes:
        assert mesh.vertices is not None and mesh.faces is not None
        assert mesh.faces.max() < len(mesh.vertices)
