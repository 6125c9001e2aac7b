"""Binary STL files of a compiled model's mesh geoms, and of its capsules and ellipsoids
(shapes a URDF cannot state), written once into a cache folder.

A mesh geom's vertices in ``model.mesh_vert`` are in the geom's frame: when it compiles,
MuJoCo moves each mesh to its inertial frame and moves the geom by as much, so the geom's
``geom_pos``/``geom_quat`` place the file exactly. Capsules and ellipsoids are tessellated
in their geom frame (axis along z), :data:`SEGMENTS` around and :data:`RINGS` per pole.

Each file is named after the SHA-256 of its bytes and written only when absent (a temporary
file renamed into place), so processes can share the folder and a second export of the same
model writes nothing. The folder is ``meshes/`` in the model cache
(:func:`~openral_mujoco.model_cache.cache_folder`), or ``openral-meshes`` in the temporary
directory when that cache is off. Nothing prunes it; it holds one file per distinct shape.
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray
from openral_core.errors import OpenralError

from openral_mujoco.model_cache import cache_folder

SEGMENTS = 24
"""Vertices around the z axis of a tessellated capsule or ellipsoid."""
RINGS = 8
"""Rings of vertices from a pole to the equator of a tessellated capsule or ellipsoid."""
HEADER = b"openral binary STL".ljust(80, b"\0")
"""The 80-byte STL header (not starting with ``solid``, which readers take for ASCII)."""
TRIANGLE = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
"""One binary STL triangle record (50 bytes)."""
EXPORTED = (
    mujoco.mjtGeom.mjGEOM_MESH,
    mujoco.mjtGeom.mjGEOM_CAPSULE,
    mujoco.mjtGeom.mjGEOM_ELLIPSOID,
)
"""Geom types :meth:`MeshExporter.geom_file` writes."""

Triangles = NDArray[np.float64]
"""Triangle corners, shape (n, 3, 3) [m]: counter-clockwise seen from outside."""


class MeshExportFailed(OpenralError):
    """A mesh file could not be written; the message names the folder and the cause."""


def mesh_folder() -> Path:
    """Where mesh files go (not created here): see the module doc."""
    cache = cache_folder()
    if cache is None:
        return Path(tempfile.gettempdir()) / "openral-meshes"
    return cache / "meshes"


class MeshExporter:
    """Writes (at most once) and names the STL file of each exported geom of one model."""

    def __init__(self, model: mujoco.MjModel, folder: Path | None = None) -> None:
        """Args:
        model: The compiled model whose geoms are exported.
        folder: Where files go; default :func:`mesh_folder`.
        """
        self._model = model
        self._folder = folder if folder is not None else mesh_folder()
        self._files: dict[tuple[object, ...], Path] = {}
        self.relative_to: Path | None = None
        """Name files relative to this folder (:meth:`geom_name`); None: by file:// URI."""

    def geom_name(self, geom: int) -> str:
        """How a URDF names :meth:`geom_file`: a ``file://`` URI, or a path relative to
        :attr:`relative_to` (POSIX separators)."""
        path = self.geom_file(geom)
        if self.relative_to is None:
            return path.as_uri()
        return Path(os.path.relpath(path, self.relative_to.resolve())).as_posix()

    def geom_file(self, geom: int) -> Path:
        """The absolute path of the STL file of mesh, capsule or ellipsoid ``geom``, in the
        geom's frame [m]; written now if no such file exists yet.

        Raises:
            ValueError: ``geom`` is of another type.
            MeshExportFailed: The folder cannot be written.
        """
        model = self._model
        kind = int(model.geom_type[geom])
        size = tuple(float(v) for v in model.geom_size[geom])
        build: Callable[[], Triangles]
        if kind == mujoco.mjtGeom.mjGEOM_MESH:
            mesh = int(model.geom_dataid[geom])
            key: tuple[object, ...] = ("mesh", mesh)
            build = lambda: mesh_triangles(model, mesh)  # noqa: E731
        elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            key = ("capsule", size[0], size[1])
            build = lambda: capsule_triangles(size[0], size[1])  # noqa: E731
        elif kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
            key = ("ellipsoid", *size)
            build = lambda: ellipsoid_triangles((size[0], size[1], size[2]))  # noqa: E731
        else:
            raise ValueError(f"geom {geom} is of type {kind}, not a mesh, capsule or ellipsoid")
        if key not in self._files:
            self._files[key] = self._write(stl_bytes(build()))
        return self._files[key]

    def _write(self, data: bytes) -> Path:
        """The file holding ``data``, named after its digest; written if absent."""
        path = self._folder / (hashlib.sha256(data).hexdigest()[:32] + ".stl")
        if path.is_file() and path.stat().st_size == len(data):
            return path.resolve()
        try:
            self._folder.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(dir=self._folder, suffix=".part")
            try:
                with os.fdopen(handle, "wb") as stream:
                    stream.write(data)
                Path(temporary).replace(path)
            finally:
                with contextlib.suppress(OSError):
                    Path(temporary).unlink(missing_ok=True)
        except OSError as error:
            raise MeshExportFailed(
                f"cannot write mesh files to {self._folder}: {error.strerror or error}; set "
                "OPENRAL_MODEL_CACHE to a writable folder"
            ) from None
        return path.resolve()


def mesh_triangles(model: mujoco.MjModel, mesh: int) -> Triangles:
    """The compiled triangles of mesh ``mesh`` [m], in the frame of a geom using it."""
    first, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    vertices = np.asarray(model.mesh_vert[first : first + count], dtype=np.float64)
    face, faces = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    indices = np.asarray(model.mesh_face[face : face + faces], dtype=np.int64)
    return vertices[indices]


def stl_bytes(triangles: Triangles) -> bytes:
    """Binary STL of ``triangles`` (unit normals; 0 for a degenerate triangle)."""
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    records = np.zeros(len(triangles), dtype=TRIANGLE)
    records["normal"] = normals
    records["vertices"] = triangles
    count = np.array([len(triangles)], dtype="<u4")
    return HEADER + count.tobytes() + records.tobytes()


def capsule_triangles(radius: float, half_length: float) -> Triangles:
    """A capsule along z: a cylinder of ``radius`` and ``2 * half_length`` [m] between two
    hemispheres."""
    angles = [math.pi / 2 * (1 - k / RINGS) for k in range(RINGS)]  # pole to equator
    top = [(radius * math.cos(a), half_length + radius * math.sin(a)) for a in angles]
    equator = [(radius, half_length), (radius, -half_length)]
    bottom = [(r, -z) for r, z in reversed(top)]
    return _lathe([*top, *equator, *bottom][1:-1], top[0][1], bottom[-1][1])


def ellipsoid_triangles(radii: tuple[float, float, float]) -> Triangles:
    """An ellipsoid with semi-axes ``radii`` along x, y and z [m]."""
    angles = [math.pi / 2 - math.pi * k / (2 * RINGS) for k in range(1, 2 * RINGS)]
    sphere = _lathe([(math.cos(a), math.sin(a)) for a in angles], 1.0, -1.0)
    return sphere * np.asarray(radii, dtype=np.float64)


def _lathe(profile: list[tuple[float, float]], top: float, bottom: float) -> Triangles:
    """The closed surface swept around z by ``profile`` (radius, z) [m], listed from the
    top pole (at z = ``top``) down to the bottom pole (at z = ``bottom``), both excluded."""
    angles = np.arange(SEGMENTS) * (2 * math.pi / SEGMENTS)
    around = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    rings = np.array([[(r * c, r * s, z) for c, s in around] for r, z in profile], dtype=np.float64)
    following = np.roll(np.arange(SEGMENTS), -1)
    upper, lower = rings[:-1], rings[1:]
    a, b, c, d = upper, lower, lower[:, following], upper[:, following]
    bands = np.concatenate([np.stack([a, b, c], axis=2), np.stack([a, c, d], axis=2)], axis=1)
    first, last = rings[0], rings[-1]
    cap_top = np.stack([np.broadcast_to([0.0, 0.0, top], first.shape), first, first[following]], 1)
    cap_bottom = np.stack(
        [last, np.broadcast_to([0.0, 0.0, bottom], last.shape), last[following]], 1
    )
    return np.concatenate([cap_top, bands.reshape(-1, 3, 3), cap_bottom])
