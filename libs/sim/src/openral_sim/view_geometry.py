"""What a viewer draws of a MuJoCo model: its body tree, each body's visible geoms, and the
body poses of a tick relative to their parents.

Pure functions of ``(model, data)``, no viewer involved: :mod:`openral_sim.browser_view`
sends them to Rerun. A body's entity path follows the kinematic tree
(``world/<link0>/<link1>/…``), so a viewer's entity tree is the scene's frame tree. Geoms
are drawn as MuJoCo's viewer draws them by default: groups 0-2, not fully transparent, in
their material's colour when they have one. Only bodies that can move relative to their
parent (a joint, or a mocap body) need a pose after the first tick.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import IntEnum

import mujoco
import numpy as np
import numpy.typing as npt

from openral_sim.frame_tree import in_parent_frames

FloatArray = npt.NDArray[np.float64]

VISIBLE_GROUPS = 3
"""Geom groups 0..2 are drawn (MuJoCo's viewer shows these by default)."""
WORLD = "world"
"""The entity path of MuJoCo's world body."""


class GeomShape(IntEnum):
    """MuJoCo's geom types (``mjtGeom``) a viewer draws; height fields are left out."""

    PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
    SPHERE = int(mujoco.mjtGeom.mjGEOM_SPHERE)
    CAPSULE = int(mujoco.mjtGeom.mjGEOM_CAPSULE)
    ELLIPSOID = int(mujoco.mjtGeom.mjGEOM_ELLIPSOID)
    CYLINDER = int(mujoco.mjtGeom.mjGEOM_CYLINDER)
    BOX = int(mujoco.mjtGeom.mjGEOM_BOX)
    MESH = int(mujoco.mjtGeom.mjGEOM_MESH)


@dataclass(frozen=True)
class Geom:
    """One visible geom, in its body's frame."""

    path: str
    """Entity path (the body's path plus the geom's name)."""
    shape: GeomShape
    size: FloatArray
    """MuJoCo's ``geom_size`` [m]: radius, half-length, half-sizes by shape."""
    position: FloatArray
    """Position in the body frame [m]."""
    quaternion_xyzw: FloatArray
    """Orientation in the body frame (Rerun's order: x, y, z, w)."""
    rgba: tuple[int, int, int, int]
    vertices: FloatArray | None = None
    """A mesh's vertices in the geom frame [m] (None for primitives)."""
    faces: npt.NDArray[np.int32] | None = None
    """A mesh's triangles, as vertex indices."""


@dataclass(frozen=True)
class BodyTree:
    """The bodies of a model as entity paths, and which of them move."""

    paths: tuple[str, ...]
    """Entity path per body id (index 0: the world)."""
    parents: npt.NDArray[np.int32]
    moving: tuple[int, ...]
    """Ids of the bodies that can move relative to their parent."""


def _part(name: str, prefix: str, index: int) -> str:
    """A path part: the element's name with anything but letters, digits, ``_`` and ``-``
    replaced (``/`` would split the path), or ``<prefix>_<index>`` when it has none."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", name) if name else f"{prefix}_{index}"


def body_tree(model: mujoco.MjModel) -> BodyTree:
    """Entity paths along the kinematic tree, and the bodies that move."""
    paths = [WORLD]
    for body in range(1, model.nbody):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or ""
        paths.append(f"{paths[int(model.body_parentid[body])]}/{_part(name, 'body', body)}")
    moving = tuple(
        body
        for body in range(1, model.nbody)
        if model.body_jntnum[body] > 0 or model.body_mocapid[body] >= 0
    )
    return BodyTree(tuple(paths), np.asarray(model.body_parentid, dtype=np.int32), moving)


def visible_geoms(model: mujoco.MjModel, tree: BodyTree) -> list[Geom]:
    """Every geom a viewer draws (see the module doc), in its body's frame."""
    geoms = []
    for geom in range(model.ngeom):
        rgba = _rgba(model, geom)
        kind = int(model.geom_type[geom])
        if model.geom_group[geom] >= VISIBLE_GROUPS or rgba[3] == 0:
            continue
        if kind not in GeomShape._value2member_map_:
            continue
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom) or ""
        body = int(model.geom_bodyid[geom])
        vertices, faces = _mesh(model, geom) if kind == GeomShape.MESH else (None, None)
        geoms.append(
            Geom(
                path=f"{tree.paths[body]}/{_part(name, 'geom', geom)}",
                shape=GeomShape(kind),
                size=np.array(model.geom_size[geom], dtype=np.float64),
                position=np.array(model.geom_pos[geom], dtype=np.float64),
                quaternion_xyzw=_xyzw(model.geom_quat[geom]),
                rgba=rgba,
                vertices=vertices,
                faces=faces,
            )
        )
    return geoms


def _rgba(model: mujoco.MjModel, geom: int) -> tuple[int, int, int, int]:
    material = int(model.geom_matid[geom])
    rgba = model.mat_rgba[material] if material >= 0 else model.geom_rgba[geom]
    r, g, b, a = (round(255 * float(np.clip(c, 0.0, 1.0))) for c in rgba)
    return r, g, b, a


def _mesh(model: mujoco.MjModel, geom: int) -> tuple[FloatArray, npt.NDArray[np.int32]]:
    mesh = int(model.geom_dataid[geom])
    first, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    face, faces = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    vertices = np.array(model.mesh_vert[first : first + count], dtype=np.float64)
    return vertices, np.array(model.mesh_face[face : face + faces], dtype=np.int32)


def _xyzw(wxyz: npt.ArrayLike) -> FloatArray:
    w, x, y, z = np.asarray(wxyz, dtype=np.float64)
    return np.array([x, y, z, w])


def relative_poses(
    data: mujoco.MjData, tree: BodyTree, bodies: tuple[int, ...]
) -> tuple[FloatArray, FloatArray]:
    """(translations [m], quaternions x-y-z-w) of ``bodies`` in their parents' frames, from
    the world poses of the tick in ``data`` (``xpos``, ``xquat``)."""
    ids = np.asarray(bodies, dtype=np.intp)
    parents = tree.parents[ids].astype(np.intp)
    translations, wxyz = in_parent_frames(data.xpos, data.xquat, ids, parents)
    return translations, np.concatenate([wxyz[:, 1:], wxyz[:, :1]], axis=1)
