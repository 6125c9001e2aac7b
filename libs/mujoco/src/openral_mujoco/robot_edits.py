"""The edits a manifest makes to its robot's own MJCF before it is compiled, in one place:
gravity compensation (:mod:`openral_mujoco.gravity`) and lighter visual meshes
(:mod:`openral_mujoco.visual_meshes`).

The robot's compiled model, the robot alone (its URDF) and every composed scene read the file
through :func:`edit_robot_spec`, so all of them hold the same bodies and meshes;
:func:`robot_cache_kind` names the edits in the model cache, so a model compiled with other
edits is never read for it.
"""

from __future__ import annotations

import mujoco
from openral_core.located import error_at
from openral_core.models import RobotDescription

from openral_mujoco.gravity import apply_gravity_compensation
from openral_mujoco.visual_meshes import InertiaChanged, lighten_visual_meshes

UNEDITED = "robot"
"""Model-cache kind of a robot model compiled from its file as it is."""


def robot_cache_kind(robot: RobotDescription) -> str:
    """The model-cache kind of ``robot``'s own model (each number changes when its edit
    does)."""
    kind, sim = UNEDITED, robot.sim
    if sim is not None and sim.gravity_compensation:
        kind += "+gravcomp-1"
    if sim is not None and sim.visual_mesh_faces is not None:
        kind += f"+faces-{sim.visual_mesh_faces}-1"
    return kind


def edit_robot_spec(spec: mujoco.MjSpec, robot: RobotDescription) -> mujoco.MjSpec:
    """``spec`` (the robot's own file) with every edit its manifest asks for.

    Raises:
        ManifestError: At ``sim.visual_mesh_faces`` when simplifying would change an inertia.
    """
    apply_gravity_compensation(spec, robot)
    faces = robot.sim.visual_mesh_faces if robot.sim is not None else None
    if faces is not None:
        try:
            lighten_visual_meshes(spec, faces)
        except InertiaChanged as error:
            raise error_at(robot, ("sim", "visual_mesh_faces"), str(error)) from None
    return spec
