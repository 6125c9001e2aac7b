"""Fewer faces on a robot's heavy visual meshes (``sim.visual_mesh_faces``).

Offscreen cameras render on the CPU (Mesa's llvmpipe), where a frame costs what its
triangles cost, whatever its size: the Panda's 135k visual faces take ~14 ms a frame at 32 or
256 px alike. A mesh that only shows (its geoms collide with nothing) and has more faces than
the manifest allows is simplified by quadric edge collapse (fast-simplification) before the
scene is compiled. Nothing physical may change: collision meshes are left alone, and the
compiled masses, inertias and inertial frames must come out identical (a body that takes its
inertia from a visual mesh would not: :class:`InertiaChanged`). A mesh with texture
coordinates is kept as it is (the simplifier drops them).

MuJoCo stores a compiled mesh centred on its own frame (``mesh_pos``, ``mesh_quat``) with
each face's three corners as separate vertices; both are undone before simplifying (corners
welded, vertices put back in the file's frame), so the compiler places the new mesh exactly
where the old one was.
"""

from __future__ import annotations

import fast_simplification
import mujoco
import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


class InertiaChanged(Exception):
    """Simplifying would change a body's mass or inertia."""


INERTIAL = ("body_mass", "body_inertia", "body_ipos", "body_iquat")
"""What the compiled bodies must keep exactly."""


def lighten_visual_meshes(spec: mujoco.MjSpec, max_faces: int) -> int:
    """Simplify, in ``spec``, every visual-only mesh with more than ``max_faces`` faces to
    about that many; the number of meshes simplified.

    Raises:
        InertiaChanged: A body's inertia depends on a mesh that was simplified (``spec`` is
            then left half edited: compile nothing from it).
    """
    model = spec.copy().compile()
    simplified = _simplify(spec, model, max_faces)
    if simplified:
        changed = spec.copy().compile()
        moved = [k for k in INERTIAL if not np.array_equal(getattr(model, k), getattr(changed, k))]
        if moved:
            raise InertiaChanged(
                f"simplifying the visual meshes changes {', '.join(moved)}: a body takes its "
                "inertia from a visual mesh; remove visual_mesh_faces or give the body an inertial"
            )
    return simplified


def _simplify(spec: mujoco.MjSpec, model: mujoco.MjModel, max_faces: int) -> int:
    """Simplify the heavy visual meshes of ``spec`` (``model`` is it compiled); how many."""
    visual = _visual_only(model)
    changed = 0
    for index, mesh in enumerate(spec.meshes):
        heavy = model.mesh_facenum[index] > max_faces
        if index not in visual or not heavy or model.mesh_texcoordadr[index] >= 0:
            continue
        vertices, triangles = _simplified(model, index, max_faces)
        mesh.name = model.mesh(index).name  # a mesh without a file needs its own name
        mesh.file = ""
        mesh.scale = [1.0, 1.0, 1.0]
        mesh.uservert = vertices.ravel().tolist()
        mesh.userface = triangles.ravel().tolist()
        mesh.usernormal, mesh.userfacenormal = [], []
        mesh.usertexcoord, mesh.userfacetexcoord = [], []
        changed += 1
    return changed


def _visual_only(model: mujoco.MjModel) -> set[int]:
    """Ids of the meshes whose every geom collides with nothing."""
    shown: set[int] = set()
    touching: set[int] = set()
    for geom in range(model.ngeom):
        if model.geom_type[geom] != mujoco.mjtGeom.mjGEOM_MESH:
            continue
        mesh = int(model.geom_dataid[geom])
        if model.geom_contype[geom] == 0 and model.geom_conaffinity[geom] == 0:
            shown.add(mesh)
        else:
            touching.add(mesh)
    return shown - touching


def _simplified(
    model: mujoco.MjModel, index: int, max_faces: int
) -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """Mesh ``index`` with at most about ``max_faces`` faces, in its file's frame."""
    start, count = model.mesh_vertadr[index], model.mesh_vertnum[index]
    first, faces = model.mesh_faceadr[index], model.mesh_facenum[index]
    corners = np.asarray(model.mesh_vert[start : start + count], dtype=np.float64)
    welded, which = np.unique(corners, axis=0, return_inverse=True)
    triangles = which.reshape(-1)[model.mesh_face[first : first + faces]]
    points, kept = fast_simplification.simplify(
        welded, triangles, target_reduction=1.0 - max_faces / faces
    )
    rotation = np.empty(9)
    mujoco.mju_quat2Mat(rotation, model.mesh_quat[index])
    in_file = np.asarray(points, dtype=np.float64) @ rotation.reshape(3, 3).T
    return in_file + model.mesh_pos[index], np.asarray(kept, dtype=np.int64)
