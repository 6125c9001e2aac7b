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

from openral_core.loaded import LoadedRobot
from openral_mujoco.robot_tree import robot_tree
from openral_mujoco.srdf import srdf_text
from openral_mujoco.urdf import urdf_text

from openral_sim.frame_tree import FrameTree
from openral_sim.scene_base import robot_alone


def robot_description(robot: LoadedRobot) -> str:
    """The robot's URDF text; its mesh files are written to the mesh cache
    (:mod:`openral_mujoco.mesh_export`) when not there yet.

    Raises:
        ManifestError: The robot's model does not load or disagrees with its manifest.
        TreeUnsupported: The model has a joint or body layout a URDF cannot state.
        MeshExportFailed: A mesh file could not be written.
    """
    alone = robot_alone(robot)
    tree = robot_tree(alone.model, robot.description, robot.tables, alone.addresses)
    return urdf_text(tree, alone.model, robot.name)


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
    return urdf_text(frames.tree, frames.model, name)


def scene_semantic_description(frames: FrameTree, robot: LoadedRobot) -> str:
    """The SRDF of ``robot`` as a running scene holds it (its frame tree's model): the
    text :func:`robot_semantic_description` returns."""
    return srdf_text(frames.tree, frames.model, robot.description, robot.tables)
