"""The robot's URDF: what the ROS graph publishes on ``/robot_description`` and what
``openral robot urdf`` writes.

Read from the robot by itself (with its mobile base, if any; :func:`robot_alone`), so the
links, joints and meshes are the simulated robot's, named as ROS names them
(:mod:`openral_mujoco.robot_tree`, :mod:`openral_mujoco.urdf`).

Example::

    text = robot_description(open_robot_by_id("franka_panda"))
"""

from __future__ import annotations

from openral_core.loaded import LoadedRobot
from openral_mujoco.robot_tree import robot_tree
from openral_mujoco.urdf import urdf_text

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
