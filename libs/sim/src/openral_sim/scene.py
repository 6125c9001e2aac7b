"""Build the SimRollout a deploy-scene file describes."""

from __future__ import annotations

import importlib
from pathlib import Path

from openral_core.errors import UnknownRobot
from openral_core.loader import load_scene
from openral_core.located import error_at
from openral_core.registry import load_robot_by_id

from openral_sim.rollout import SimRollout


def build_sim_env_from_yaml(path: str | Path, robot_id_fallback: str | None = None) -> SimRollout:
    """Load a deploy-scene file and build its backend.

    Args:
        path: The scene file (schema ``schema/scene.schema.json``).
        robot_id_fallback: Robot to use when the file names none.

    Raises:
        ManifestError: The file is invalid, names no or an unknown robot, or cannot be built
            for its robot; every problem as ``file:line:col: field: message`` of the scene
            file or the robot's manifest.
    """
    file = Path(path)
    scene = load_scene(file)
    robot_id = scene.robot_id or robot_id_fallback
    if robot_id is None:
        raise error_at(scene, (), "the scene names no robot and none was given; add robot_id")
    try:
        robot = load_robot_by_id(robot_id)
    except UnknownRobot as error:
        raise error_at(scene, ("robot_id",), str(error)) from None
    if scene.scene.backend.value == "robosuite":
        try:
            backend = importlib.import_module("openral_sim.robosuite_backend")
        except ModuleNotFoundError as error:
            message = f"the robosuite backend is unavailable ({error})"
            raise error_at(scene, ("scene", "backend"), message) from None
        rollout: SimRollout = backend.build_robosuite_rollout(
            scene.model_copy(update={"robot_id": robot_id})
        )
        return rollout
    from openral_sim.native_scene import NativeScene

    return NativeScene(scene, robot)
