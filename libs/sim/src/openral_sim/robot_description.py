"""The robot's URDF: what the ROS graph publishes on ``/robot_description`` and what
``openral robot urdf`` writes.

Read from the robot by itself (with its mobile base, if any; :func:`robot_alone`), so the
links, joints and meshes are the simulated robot's, named as ROS names them
(:mod:`openral_mujoco.robot_tree`, :mod:`openral_mujoco.urdf`).

A running scene publishes the same document without composing the robot again:
:func:`scene_robot_description` reads it from the scene's own model and frame tree (a
tenth of the time, so the graph's start-up work beside its control loop stays short).

Example::

    text = robot_description(open_robot_by_id("franka_panda"))
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
from openral_core.loaded import LoadedRobot
from openral_mujoco.mesh_export import MeshExporter
from openral_mujoco.robot_tree import robot_tree
from openral_mujoco.srdf import srdf_text
from openral_mujoco.state import FloatArray
from openral_mujoco.urdf import FixedFrame, urdf_text

from openral_sim.frame_tree import FrameTree
from openral_sim.scene_base import robot_alone


def robot_description(robot: LoadedRobot, beside: Path | None = None) -> str:
    """The robot's URDF text; its mesh files are written to the mesh cache
    (:mod:`openral_mujoco.mesh_export`) when not there yet and named by ``file://`` URI, or,
    with ``beside`` (the URDF's folder), written to ``beside/meshes`` and named by relative
    path (what MuJoCo's URDF compiler reads).

    Raises:
        ManifestError: The robot's model does not load or disagrees with its manifest.
        TreeUnsupported: The model has a joint or body layout a URDF cannot state.
        MeshExportFailed: A mesh file could not be written.
    """
    alone = robot_alone(robot)
    tree = robot_tree(alone.model, robot.description, robot.tables, alone.addresses)
    if beside is None:
        return urdf_text(tree, alone.model, robot.name)
    meshes = MeshExporter(alone.model, beside / "meshes")
    return urdf_text(tree, alone.model, robot.name, meshes, relative_to=beside)


def robot_semantic_description(robot: LoadedRobot) -> str:
    """The robot's SRDF text (:mod:`openral_mujoco.srdf`), on the URDF's names.

    Raises:
        ManifestError: The robot's model does not load or disagrees with its manifest.
        TreeUnsupported: The model has a joint or body layout a URDF cannot state.
    """
    alone = robot_alone(robot)
    tree = robot_tree(alone.model, robot.description, robot.tables, alone.addresses)
    return srdf_text(tree, alone.model, robot.description, robot.tables)


def scene_robot_description(frames: FrameTree, name: str) -> str:
    """The URDF of robot ``name`` as a running scene holds it, read from the scene's model
    through its frame tree: the text :func:`robot_description` returns.

    Raises:
        TreeUnsupported: Two links or two joints would share a name.
        MeshExportFailed: A mesh file could not be written.
    """
    return urdf_text(frames.tree, frames.model, name, frames=sensor_frames(frames))


def sensor_frames(frames: FrameTree) -> list[FixedFrame]:
    """The sensors' frames fixed on the robot (a camera's link and optical frame, an F-T,
    lidar or IMU site), each posed in its parent, parents first: what robot_state_publisher
    needs to place them from the URDF alone. A sensor on a moving mount or off the robot
    (a scene camera) is not the robot's: it stays on ``/tf``."""
    data = mujoco.MjData(frames.model)
    mujoco.mj_forward(frames.model, data)
    sample = frames.sample(data)
    on_robot = {link.name for link in frames.tree.links}
    rows = []
    for row in frames.sensor_rows:
        frame = frames.frames[row]
        if frame.static and frame.parent in on_robot:
            on_robot.add(frame.name)
            rows.append(row)
    positions, quats = sample.relative(frames, np.array(rows, dtype=np.intp))
    return [
        FixedFrame(frames.frames[row].name, frames.frames[row].parent, _vec(p), _quat(q))
        for row, p, q in zip(rows, positions, quats, strict=True)
    ]


def urdf_transforms(frames: FrameTree) -> frozenset[str]:
    """The frames whose transform the scene's URDF holds (a robot_state_publisher sends
    them): the robot's links below its root and :func:`sensor_frames`. The root's own
    transform (world or odometry → base) is no URDF's."""
    links = {link.name for link in frames.tree.links} - {frames.tree.base}
    return frozenset(links | {frame.name for frame in sensor_frames(frames)})


def _vec(values: FloatArray) -> tuple[float, float, float]:
    return float(values[0]), float(values[1]), float(values[2])


def _quat(values: FloatArray) -> tuple[float, float, float, float]:
    return float(values[0]), float(values[1]), float(values[2]), float(values[3])


def scene_semantic_description(frames: FrameTree, robot: LoadedRobot) -> str:
    """The SRDF of ``robot`` as a running scene holds it (its frame tree's model): the
    text :func:`robot_semantic_description` returns."""
    return srdf_text(frames.tree, frames.model, robot.description, robot.tables)
