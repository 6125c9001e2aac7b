"""URDF text of a robot's tree (:mod:`openral_mujoco.robot_tree`) and the model it was read
from: what ROS publishes on ``/robot_description``.

Each link of the tree is a ``<link>`` named after it, the base frame the root. A body's link
holds its ``<inertial>`` (none for a massless body), a ``<visual>`` per geom MuJoCo's viewer
shows by default (group 0-2, not transparent; coloured as the viewer colours it: the geom's
``rgba`` unless it is the default and the geom has a material) and a ``<collision>`` per geom
that collides (``contype`` or ``conaffinity`` set). Boxes, spheres and cylinders are URDF
shapes; meshes, capsules and ellipsoids are STL files (:mod:`openral_mujoco.mesh_export`);
planes, height fields and SDFs are left out.

Each other link hangs from its parent by a ``<joint>``: the tree's joint, else a fixed joint
``<child>_fixed`` unless ``frames.joints`` names it. A revolute joint whose axis does not
pass through the child's origin (a non-zero ``anchor``) becomes the joint into an extra link
``<child>_axis`` at the anchor, then a fixed joint ``<child>_fixed`` back to the child's
origin.

The text is deterministic: the same tree and model give the same bytes (numbers as their
shortest round-trip ``repr``, no dates).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from openral_mujoco.errors import TreeUnsupported
from openral_mujoco.mesh_export import EXPORTED, MeshExporter
from openral_mujoco.robot_tree import Quaternion, RobotTree, TreeLink, Vector

VISIBLE_GROUPS = (0, 1, 2)
"""Geom groups MuJoCo's viewer shows by default."""
DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)
"""A geom's ``rgba`` when its MJCF sets none (then its material, if any, colours it)."""
GIMBAL_LOCK = 1e-8
"""|cos(pitch)| below which roll is taken as 0 and yaw carries the whole turn."""
SKIPPED = (mujoco.mjtGeom.mjGEOM_PLANE, mujoco.mjtGeom.mjGEOM_HFIELD, mujoco.mjtGeom.mjGEOM_SDF)
"""Geom types a URDF leaves out."""
IDENTITY: Quaternion = (1.0, 0.0, 0.0, 0.0)
ORIGIN_DECIMALS = 12
"""Decimals of an origin's numbers [m, rad]."""


@dataclass(frozen=True)
class FixedFrame:
    """A frame fixed on a link of the tree (a sensor's): no geometry, a fixed joint."""

    name: str
    parent: str
    position: Vector
    quat: Quaternion


def urdf_text(
    tree: RobotTree,
    model: mujoco.MjModel,
    name: str,
    meshes: MeshExporter | None = None,
    frames: Sequence[FixedFrame] = (),
    relative_to: Path | None = None,
) -> str:
    """The URDF of ``tree`` (read from ``model``) as a ``<robot name=name>`` document.

    Args:
        tree: The robot's tree.
        model: The compiled model the tree was read from (geoms, inertias, meshes).
        name: The robot's name.
        meshes: Writes the mesh files; default a :class:`MeshExporter` of ``model``.
        frames: Frames to add as empty links on fixed joints ``<frame>_joint``, parents
            first (a sensor's frames, :mod:`openral_sim.robot_description`).
        relative_to: Name mesh files by their path relative to this folder (the URDF's: the
            form MuJoCo's URDF compiler reads) instead of by ``file://`` URI (rviz2's).

    Raises:
        TreeUnsupported: Two links or two joints would share a name.
        MeshExportFailed: A mesh file could not be written.
    """
    exporter = meshes if meshes is not None else MeshExporter(model)
    exporter.relative_to = relative_to
    _require_unique_names(tree)
    robot = ET.Element("robot", name=name)
    for link in tree.links:
        if link.parent is not None:
            _add_joints(robot, link)
        robot.append(_link(model, link, exporter))
    for frame in frames:
        _fixed(robot, frame.parent, frame.name, frame.position, frame.quat, f"{frame.name}_joint")
        ET.SubElement(robot, "link", name=frame.name)
    ET.indent(robot, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def _require_unique_names(tree: RobotTree) -> None:
    links = [link.name for link in tree.links]
    joints = []
    for link in tree.links:
        if link.parent is None:
            continue
        if link.joint is None:
            joints.append(_fixed_name(link))
        if _anchored(link):
            joints.append(f"{link.name}_fixed")
        if link.joint is not None:
            joints.append(link.joint.name)
        if _anchored(link):
            links.append(f"{link.name}_axis")
    for kind, names in (("link", links), ("joint", joints)):
        twice = sorted(n for n, count in Counter(names).items() if count > 1)
        if twice:
            raise TreeUnsupported(
                f"the URDF would hold two {kind}s named {twice[0]!r} (a fixed joint is named "
                "'<child>_fixed', the link of an offset axis '<child>_axis'); rename one"
            )


def _anchored(link: TreeLink) -> bool:
    """True when ``link``'s joint turns about an axis off its origin."""
    joint = link.joint
    return joint is not None and joint.kind != "prismatic" and any(joint.anchor)


# -- joints ----------------------------------------------------------------------------------


def _add_joints(robot: ET.Element, link: TreeLink) -> None:
    """The joint(s) hanging ``link`` from its parent (and the axis link between them)."""
    assert link.parent is not None
    joint = link.joint
    if joint is None:
        _fixed(robot, link.parent, link.name, link.position, link.quat, _fixed_name(link))
        return
    parent_side = link.name
    position = link.position
    if _anchored(link):
        parent_side = f"{link.name}_axis"
        shift = np.empty(3)
        mujoco.mju_rotVecQuat(shift, np.asarray(joint.anchor), np.asarray(link.quat))
        x, y, z = (p + float(s) for p, s in zip(link.position, shift, strict=True))
        position = (x, y, z)
    element = ET.SubElement(robot, "joint", name=joint.name, type=joint.kind)
    _origin(element, position, link.quat)
    ET.SubElement(element, "parent", link=link.parent)
    ET.SubElement(element, "child", link=parent_side)
    ET.SubElement(element, "axis", xyz=_numbers(joint.axis))
    limit = {"effort": _number(joint.effort), "velocity": _number(joint.velocity)}
    if joint.kind != "continuous":
        limit = {"lower": _number(joint.lower), "upper": _number(joint.upper), **limit}
    ET.SubElement(element, "limit", limit)
    if joint.mimic is not None:
        mimic = joint.mimic
        ET.SubElement(
            element,
            "mimic",
            joint=mimic.joint,
            multiplier=_number(mimic.multiplier),
            offset=_number(mimic.offset),
        )
    if _anchored(link):
        ET.SubElement(robot, "link", name=parent_side)
        back = (-joint.anchor[0], -joint.anchor[1], -joint.anchor[2])
        _fixed(robot, parent_side, link.name, back, IDENTITY)


def _fixed_name(link: TreeLink) -> str:
    """The fixed joint into ``link``: as ``frames.joints`` names it, else ``<link>_fixed``."""
    return link.fixed_joint or f"{link.name}_fixed"


def _fixed(
    robot: ET.Element,
    parent: str,
    child: str,
    position: Vector,
    quat: Quaternion,
    name: str = "",
) -> None:
    element = ET.SubElement(robot, "joint", name=name or f"{child}_fixed", type="fixed")
    _origin(element, position, quat)
    ET.SubElement(element, "parent", link=parent)
    ET.SubElement(element, "child", link=child)


# -- links -----------------------------------------------------------------------------------


def _link(model: mujoco.MjModel, link: TreeLink, meshes: MeshExporter) -> ET.Element:
    element = ET.Element("link", name=link.name)
    body = link.body
    if body < 0:
        return element
    if model.body_mass[body] > 0:
        _inertial(element, model, body)
    first, count = int(model.body_geomadr[body]), int(model.body_geomnum[body])
    shown = 0
    for geom in range(first, first + count):
        if int(model.geom_type[geom]) in SKIPPED:
            continue
        rgba = _rgba(model, geom)
        if int(model.geom_group[geom]) in VISIBLE_GROUPS and rgba[3] > 0:
            visual = ET.SubElement(element, "visual")
            _place(visual, model, geom, meshes)
            material = ET.SubElement(visual, "material", name=f"{link.name}_material_{shown}")
            ET.SubElement(material, "color", rgba=" ".join(str(np.float32(v)) for v in rgba))
            shown += 1
        if model.geom_contype[geom] or model.geom_conaffinity[geom]:
            _place(ET.SubElement(element, "collision"), model, geom, meshes)
    return element


def _inertial(link: ET.Element, model: mujoco.MjModel, body: int) -> None:
    """Mass [kg] and principal inertia [kg·m²] at the body's inertial frame."""
    inertial = ET.SubElement(link, "inertial")
    _origin(inertial, _vector(model.body_ipos[body]), _quaternion(model.body_iquat[body]))
    ET.SubElement(inertial, "mass", value=_number(model.body_mass[body]))
    ixx, iyy, izz = (_number(v) for v in model.body_inertia[body])
    zero = "0"
    ET.SubElement(inertial, "inertia", ixx=ixx, ixy=zero, ixz=zero, iyy=iyy, iyz=zero, izz=izz)


def _rgba(model: mujoco.MjModel, geom: int) -> tuple[float, float, float, float]:
    """The geom's colour as MuJoCo's viewer draws it."""
    own = tuple(float(v) for v in model.geom_rgba[geom])
    material = int(model.geom_matid[geom])
    source = model.mat_rgba[material] if material >= 0 and own == DEFAULT_RGBA else own
    r, g, b, a = (float(v) for v in source)
    return r, g, b, a


def _place(element: ET.Element, model: mujoco.MjModel, geom: int, meshes: MeshExporter) -> None:
    """The geom's ``<origin>`` in its body and its ``<geometry>``."""
    _origin(element, _vector(model.geom_pos[geom]), _quaternion(model.geom_quat[geom]))
    geometry = ET.SubElement(element, "geometry")
    kind = int(model.geom_type[geom])
    size = [float(v) for v in model.geom_size[geom]]
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        ET.SubElement(geometry, "box", size=_numbers([2 * s for s in size]))
    elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        ET.SubElement(geometry, "sphere", radius=_number(size[0]))
    elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        ET.SubElement(geometry, "cylinder", radius=_number(size[0]), length=_number(2 * size[1]))
    elif kind in EXPORTED:
        ET.SubElement(geometry, "mesh", filename=meshes.geom_name(geom))
    else:
        raise TreeUnsupported(f"geom {geom} has type {kind}, which a URDF cannot state")


# -- numbers and frames ----------------------------------------------------------------------


def _origin(element: ET.Element, position: Vector, quat: Quaternion) -> None:
    """An ``<origin>`` at 1e-12 m and rad: poses composed from the model's world poses carry
    rounding noise (0.33299999999999996 for 0.333) that would make two readings of one
    robot differ."""
    xyz = " ".join(_number(round(v, ORIGIN_DECIMALS)) for v in position)
    angles = " ".join(_number(round(v, ORIGIN_DECIMALS)) for v in rpy(quat))
    ET.SubElement(element, "origin", xyz=xyz, rpy=angles)


def rpy(quat: Quaternion) -> Vector:
    """URDF roll, pitch and yaw [rad] of rotation ``quat`` (w, x, y, z), so that its matrix is
    ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``; at gimbal lock roll is 0."""
    q = np.asarray(quat, dtype=np.float64)
    matrix = np.empty(9)
    mujoco.mju_quat2Mat(matrix, q / np.linalg.norm(q))
    r = matrix.reshape(3, 3)
    cos_pitch = math.hypot(r[0, 0], r[1, 0])
    pitch = math.atan2(-r[2, 0], cos_pitch)
    if cos_pitch < GIMBAL_LOCK:
        return 0.0, pitch, math.atan2(-r[0, 1], r[1, 1])
    return math.atan2(r[2, 1], r[2, 2]), pitch, math.atan2(r[1, 0], r[0, 0])


def _number(value: float) -> str:
    """Shortest text reading back as the same float (no ``-0``)."""
    number = float(value)
    return "0" if number == 0.0 else repr(number)


def _numbers(values: tuple[float, ...] | list[float]) -> str:
    return " ".join(_number(v) for v in values)


def _vector(values: np.ndarray) -> Vector:
    x, y, z = (float(v) for v in values)
    return x, y, z


def _quaternion(values: np.ndarray) -> Quaternion:
    w, x, y, z = (float(v) for v in values)
    return w, x, y, z
