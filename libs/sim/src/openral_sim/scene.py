"""Build the SimRollout a loaded deploy scene describes, for a loaded robot.

The CLI and the node load the scene file and the robot once, at the top, and hand both
down: :func:`build_scene` reads no file. :func:`scene_robot` loads the robot a scene names,
with errors located at the scene's ``robot_id``.

Example::

    scene = load_scene(Path("robots/franka_panda/scenes/tabletop.yaml"))
    rollout = build_scene(scene, scene_robot(scene))
"""

from __future__ import annotations

from pathlib import Path

from openral_core import LoadedRobot, open_robot_by_id
from openral_core.errors import UnknownRobot
from openral_core.loader import load_scene
from openral_core.located import error_at
from openral_core.models import Backend, DeployScene

from openral_sim.rollout import SimRollout
from openral_sim.scene_checks import check_scene_cameras


def scene_robot(scene: DeployScene, robot_id_fallback: str | None = None) -> LoadedRobot:
    """Load the robot ``scene`` names (else ``robot_id_fallback``) from ``robots/``.

    Raises:
        ManifestError: The scene names no robot and none was given, another robot than
            the one given, or an unknown one (located at the scene's ``robot_id``); or the
            robot's manifest is invalid.
        StaleTables: The robot's generated tables were made from another manifest.
    """
    robot_id = scene.robot_id or robot_id_fallback
    if robot_id_fallback is not None and robot_id != robot_id_fallback:
        message = f"the scene is for {robot_id}, not {robot_id_fallback}"
        raise error_at(scene, ("robot_id",), message)
    if robot_id is None:
        raise error_at(scene, (), "the scene names no robot and none was given; add robot_id")
    try:
        return open_robot_by_id(robot_id)
    except UnknownRobot as error:
        raise error_at(scene, ("robot_id",), str(error)) from None


def check_scene_robot(scene: DeployScene, robot: LoadedRobot) -> None:
    """Refuse a scene that names another robot than ``robot`` (never a silent swap).

    Raises:
        ManifestError: At the scene's ``robot_id``.
    """
    if scene.robot_id is not None and scene.robot_id != robot.name:
        message = f"the scene is for {scene.robot_id}, not {robot.name}"
        raise error_at(scene, ("robot_id",), message)


def build_scene(
    scene: DeployScene,
    robot: LoadedRobot,
    *,
    render_observations: bool = True,
    frame_rate_hz: float | None = None,
) -> SimRollout:
    """The backend ``scene`` names, built for ``robot``; reads no file but the robot's model.

    ``render_observations=False`` builds a native scene that renders nothing into its
    observations (``deploy sim`` renders frames on demand instead); robosuite renders its own.
    ``frame_rate_hz`` overrides the rate of every camera and lidar in the observations
    (:func:`~openral_sim.sensor_schedule.sensor_rates`; ``math.inf``: every step).

    Raises:
        ManifestError: The scene is for another robot or cannot be built for this one;
            every problem as ``file:line:col: field: message`` of the scene file or the
            robot's manifest.
    """
    check_scene_robot(scene, robot)
    if scene.scene.backend is Backend.robosuite:
        try:
            from openral_sim.robosuite_backend import build_robosuite_rollout
        except ModuleNotFoundError as error:
            message = f"the robosuite backend is unavailable ({error})"
            raise error_at(scene, ("scene", "backend"), message) from None
        return build_robosuite_rollout(scene, robot.description, frame_rate_hz=frame_rate_hz)
    from openral_sim.native_scene import NativeScene

    check_scene_cameras(scene, robot.description)
    native = NativeScene(scene, robot, render_observations=render_observations)
    if frame_rate_hz is not None:
        native.sensors.reschedule(1.0 / native.control_period_s, frame_rate_hz)
    return native


def build_sim_env_from_yaml(path: str | Path, robot_id_fallback: str | None = None) -> SimRollout:
    """Load a deploy-scene file and its robot, then :func:`build_scene` (tests and tools
    that start from a file; the CLI and the node load once and call :func:`build_scene`).

    Raises:
        ManifestError: The file is invalid, names no or an unknown robot, or cannot be built
            for its robot (located).
        StaleTables: The robot's generated tables were made from another manifest.
    """
    scene = load_scene(Path(path))
    return build_scene(scene, scene_robot(scene, robot_id_fallback))
