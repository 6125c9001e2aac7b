"""Build the SimRollout a deploy-scene file describes."""

from __future__ import annotations

import importlib
from pathlib import Path

from openral_core.errors import OpenralError, UnknownRobot
from openral_core.loader import load_scene
from openral_core.registry import load_robot_by_id

from openral_sim.rollout import SimRollout


def build_sim_env_from_yaml(path: str | Path, robot_id_fallback: str | None = None) -> SimRollout:
    """Load a deploy-scene file and build its backend.

    Args:
        path: The scene file (schema ``schema/scene.schema.json``).
        robot_id_fallback: Robot to use when the file names none.

    Raises:
        ManifestError: The file is invalid (every problem as ``file:line:col: field: msg``).
        OpenralError: No robot named, or the scene cannot be built for the robot.
    """
    file = Path(path)
    scene = load_scene(file)
    robot_id = scene.robot_id or robot_id_fallback
    if robot_id is None:
        raise OpenralError(f"{file}: robot_id: the scene names no robot and none was given")
    try:
        robot = load_robot_by_id(robot_id)
    except UnknownRobot as error:
        raise OpenralError(f"{file}: robot_id: {error}") from None
    if scene.scene.backend.value == "robosuite":
        try:
            backend = importlib.import_module("openral_sim.robosuite_backend")
        except ModuleNotFoundError as error:
            raise OpenralError(
                f"{file}: scene.backend: the robosuite backend is unavailable ({error})"
            ) from None
        try:
            rollout: SimRollout = backend.build_robosuite_rollout(
                scene.model_copy(update={"robot_id": robot_id})
            )
        except OpenralError as error:  # name the file, as the native backend does
            raise type(error)(f"{file}: {error}") from None
        return rollout
    from openral_sim.native_scene import NativeScene

    return NativeScene(scene, robot, source=file)
