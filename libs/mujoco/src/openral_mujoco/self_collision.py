"""Which pairs of a robot's links can touch, found by sampling poses: the disabled collision
pairs of its SRDF (:mod:`openral_mujoco.srdf`), as MoveIt's setup assistant finds them.

A pair is **adjacent** when one link hangs from the other, or from a link with no geometry
that hangs from it (their geometry meets at the joint by design), and **never** when no
sampled pose brings their collision geometry within :data:`MARGIN_M` of each other. Every
other pair can collide and stays checked. Poses are drawn uniformly inside each joint's
limits (a mimic joint follows its leader), from a fixed seed, so the same model gives the
same pairs. The geometry is the URDF's collision geometry (geoms with ``contype`` or
``conaffinity`` set), each grown by the margin, with MuJoCo's own pair filters (parent-child,
contype/conaffinity bits) switched off. Pairs sampling cannot judge stay checked: links
welded together (MuJoCo never collides them) and pairs the MJCF excludes.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from dataclasses import dataclass
from itertools import combinations

import mujoco
import numpy as np

from openral_mujoco.mesh_export import mesh_folder
from openral_mujoco.robot_tree import RobotTree

CACHE_VERSION = 1
"""Bumped when the way pairs are found changes (old cache files are then not read)."""
SAMPLES = 4000
"""Poses drawn per model."""
MARGIN_M = 0.01
"""Geometry this close counts as touching [m] (a pose between two samples may be closer)."""
SEED = 0


KINDS = ("adjacent", "never", "touching")
_MEMO: dict[str, LinkPairs] = {}


@dataclass(frozen=True)
class LinkPairs:
    """Collision pairs of a robot's links, each pair sorted by name."""

    adjacent: tuple[tuple[str, str], ...]
    never: tuple[tuple[str, str], ...]
    touching: tuple[tuple[str, str], ...]
    """Pairs some sampled pose brought together (not adjacent): checked by a planner."""


def cached_link_pairs(tree: RobotTree, model: mujoco.MjModel) -> LinkPairs:
    """:func:`link_pairs`, found once per robot geometry and kept in the model cache (a
    graph's start-up would otherwise sample 1-6 s of poses each time)."""
    key = _geometry_key(tree, model)
    if key in _MEMO:
        return _MEMO[key]
    file = mesh_folder().parent / "link_pairs" / f"{key}.json"
    with contextlib.suppress(OSError, ValueError, KeyError, TypeError):
        saved = json.loads(file.read_text(encoding="utf-8"))
        _MEMO[key] = pairs = LinkPairs(*(tuple(tuple(p) for p in saved[k]) for k in KINDS))
        return pairs
    pairs = link_pairs(tree, model)
    with contextlib.suppress(OSError):  # a cache that cannot be written is only slower
        file.parent.mkdir(parents=True, exist_ok=True)
        temporary = file.with_suffix(f".{os.getpid()}.part")
        temporary.write_text(json.dumps({k: getattr(pairs, k) for k in KINDS}), "utf-8")
        temporary.replace(file)
    _MEMO[key] = pairs
    return pairs


def link_pairs(tree: RobotTree, model: mujoco.MjModel, samples: int = SAMPLES) -> LinkPairs:
    """The robot's link pairs, by kind (see the module doc)."""
    geometric = _links_with_geometry(tree, model)
    adjacent = _adjacent(tree, geometric)
    touched = _touching(tree, model, geometric, samples) | _excluded(tree, model, geometric)
    touched |= _welded(tree, model, geometric)
    every = {_pair(a, b) for a, b in combinations(sorted(geometric), 2)}
    return LinkPairs(
        adjacent=tuple(sorted(adjacent)),
        never=tuple(sorted(every - adjacent - touched)),
        touching=tuple(sorted(touched - adjacent)),
    )


def _geometry_key(tree: RobotTree, model: mujoco.MjModel) -> str:
    """A digest of everything the pairs depend on: the tree (names, poses, joints), each
    link's collision geoms (type, size, pose, mesh vertices) and the sampling settings."""
    digest = hashlib.sha256(repr((CACHE_VERSION, SAMPLES, MARGIN_M, SEED)).encode())
    for link in tree.links:
        digest.update(repr((link.name, link.parent, link.position, link.quat)).encode())
        if link.joint is not None:
            joint = link.joint
            digest.update(repr((joint.name, joint.lower, joint.upper, joint.mimic)).encode())
    for name, geoms in sorted(_links_with_geometry(tree, model).items()):
        digest.update(name.encode())
        for geom in geoms:
            for values in (model.geom_type[geom], model.geom_size[geom], model.geom_pos[geom]):
                digest.update(np.asarray(values, dtype=np.float64).tobytes())
            digest.update(np.asarray(model.geom_quat[geom], dtype=np.float64).tobytes())
            mesh = int(model.geom_dataid[geom])
            if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_MESH and mesh >= 0:
                first, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
                digest.update(np.asarray(model.mesh_vert[first : first + count]).tobytes())
    return digest.hexdigest()[:32]


def _adjacent(tree: RobotTree, geometric: dict[str, list[int]]) -> set[tuple[str, str]]:
    """Each link with geometry and its nearest ancestor with geometry (a link with none in
    between, such as the Panda's flange, does not part them)."""
    parent_of = {link.name: link.parent for link in tree.links}
    pairs = set()
    for name in geometric:
        above = parent_of.get(name)
        while above is not None and above not in geometric:
            above = parent_of.get(above)
        if above is not None:
            pairs.add(_pair(name, above))
    return pairs


def _welded(
    tree: RobotTree, model: mujoco.MjModel, geometric: dict[str, list[int]]
) -> set[tuple[str, str]]:
    """Pairs rigidly fixed to one another: MuJoCo never collides them, so sampling cannot
    tell; they stay checked (the adjacent ones are disabled anyway)."""
    weld = {
        link.name: int(model.body_weldid[link.body])
        for link in tree.links
        if link.name in geometric
    }
    return {_pair(a, b) for a, b in combinations(sorted(weld), 2) if weld[a] == weld[b]}


def _links_with_geometry(tree: RobotTree, model: mujoco.MjModel) -> dict[str, list[int]]:
    """Link name → its collision geoms, for links that have any."""
    found: dict[str, list[int]] = {}
    for link in tree.links:
        if link.body < 0:
            continue
        first, count = int(model.body_geomadr[link.body]), int(model.body_geomnum[link.body])
        geoms = [
            g
            for g in range(first, first + count)
            if model.geom_contype[g] or model.geom_conaffinity[g]
        ]
        if geoms:
            found[link.name] = geoms
    return found


def _touching(
    tree: RobotTree, model: mujoco.MjModel, geometric: dict[str, list[int]], samples: int
) -> set[tuple[str, str]]:
    """Pairs of links whose geometry came within the margin in some sampled pose."""
    probe = _probe_model(model, geometric)
    data = mujoco.MjData(probe)
    link_of = {g: name for name, geoms in geometric.items() for g in geoms}
    joints = [link.joint for link in tree.links if link.joint is not None]
    by_name = {joint.name: joint for joint in joints}
    rng = np.random.default_rng(SEED)
    touched: set[tuple[str, str]] = set()
    for _ in range(samples):
        data.qpos[:] = probe.qpos0
        for joint in joints:
            if joint.mimic is None:
                data.qpos[joint.qpos] = rng.uniform(joint.lower, joint.upper)
        for joint in joints:
            if joint.mimic is not None and joint.mimic.joint in by_name:
                leader = data.qpos[by_name[joint.mimic.joint].qpos]
                data.qpos[joint.qpos] = joint.mimic.multiplier * leader + joint.mimic.offset
        mujoco.mj_kinematics(probe, data)
        mujoco.mj_collision(probe, data)
        for geom1, geom2 in data.contact.geom[: data.ncon]:
            a, b = link_of.get(int(geom1)), link_of.get(int(geom2))
            if a is not None and b is not None and a != b:
                touched.add(_pair(a, b))
    return touched


def _excluded(
    tree: RobotTree, model: mujoco.MjModel, geometric: dict[str, list[int]]
) -> set[tuple[str, str]]:
    """Pairs the MJCF excludes from contact (``<exclude>``): sampling cannot see them, so
    they stay checked."""
    name_of = {link.body: link.name for link in tree.links if link.name in geometric}
    pairs = set()
    for signature in np.asarray(model.exclude_signature, dtype=np.int64):
        a, b = name_of.get(int(signature) >> 16), name_of.get(int(signature) & 0xFFFF)
        if a is not None and b is not None:
            pairs.add(_pair(a, b))
    return pairs


def _probe_model(model: mujoco.MjModel, geometric: dict[str, list[int]]) -> mujoco.MjModel:
    """A copy of ``model`` where only the links' collision geoms collide, every pair of them,
    each grown by the margin."""
    probe = model.__copy__()
    collide = np.zeros(probe.ngeom, dtype=bool)
    collide[[g for geoms in geometric.values() for g in geoms]] = True
    probe.geom_contype[:] = np.where(collide, 1, 0)
    probe.geom_conaffinity[:] = np.where(collide, 1, 0)
    probe.geom_margin[:] = MARGIN_M
    probe.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
    return probe


def _pair(a: str, b: str | None) -> tuple[str, str]:
    assert b is not None
    return (a, b) if a < b else (b, a)
