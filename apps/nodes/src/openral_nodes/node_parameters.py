"""The manifest node's parameters: names, defaults, the ranges checked at configure, and
the robot and scene they name."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from openral_core import LoadedRobot, open_robot, open_robot_by_id
from openral_core.loader import load_scene
from openral_core.models import DeployScene
from openral_hal.factory import RealOptions, build_hal
from openral_hal.protocol import RobotHal
from openral_sim.rollout import SimRollout
from openral_sim.scene import build_scene, scene_robot

PARAMETERS: dict[str, Any] = {
    "robot_id": "",
    "manifest_path": "",
    "hal_mode": "sim",
    "sim_env_yaml": "",
    "viewer_enabled": True,
    "camera_publish_rate_hz": 0.0,
    "joint_state_rate_hz": 100.0,
    "publish_tf": True,
    "publish_static_tf": True,
    "view_port": 0,
    "transport": "",
    "calibration_file": "",
    "arm_id": "",
    "cameras": [""],
    "twin_scene": "",
    "loop_priority": 0,
}
"""Every parameter and its default. A real robot's: ``transport`` (its bus or address),
``calibration_file`` and ``arm_id`` (which calibration), ``cameras`` (``NAME=DEVICE``
strings over the manifest's devices; ``[""]`` for none, as ROS has no empty list type),
``twin_scene`` (a scene file the real robot is posed in: ``deploy real --twin``).
``loop_priority``: the control loop thread's real-time priority (1-99; 0: ordinary), as a
ros2_control driver's ``thread_priority`` (``deploy sim --loop-priority``)."""

RATE_RANGE_HZ = (0.1, 1000.0)
"""Accepted ``camera_publish_rate_hz`` (or 0) and ``joint_state_rate_hz``, inclusive [Hz]."""
BOUNDS: dict[str, tuple[tuple[float, float], str]] = {
    "camera_publish_rate_hz": (RATE_RANGE_HZ, "Hz"),
    "joint_state_rate_hz": (RATE_RANGE_HZ, "Hz"),
    "loop_priority": ((0.0, 99.0), "(real-time priority; 0: ordinary scheduling)"),
}
"""Range and unit of each bounded parameter, checked at configure."""
UNSET = {"camera_publish_rate_hz": 0.0}
"""Parameters whose value here means "not set" rather than a value to check."""


def check_rates(values: dict[str, Any]) -> None:
    """Check each bounded parameter's value against :data:`BOUNDS`.

    Raises:
        ValueError: A value outside its range (or not finite), naming the range.
    """
    for name, value in values.items():
        (low, high), unit = BOUNDS[name]
        number = float(value)
        if name in UNSET and number == UNSET[name]:
            continue
        if not (math.isfinite(number) and low <= number <= high):
            unset = f" (or {UNSET[name]:g} for each sensor's own rate)" if name in UNSET else ""
            raise ValueError(
                f"parameter {name} must be within {low:g}-{high:g} {unit}{unset}, got {number:g}"
            )


def robot_and_scene(
    robot_id: str, manifest_path: str, sim_env_yaml: str
) -> tuple[LoadedRobot, DeployScene | None]:
    """The robot and the scene the parameters name, each read from its file once (the
    scene's robot is checked against the robot by ``build_hal``): ``manifest_path`` as it
    reads, else ``robot_id`` from ``robots/``, else the robot the scene names.

    Raises:
        ValueError: ``robot_id`` and ``manifest_path`` disagree, or nothing names a robot.
        OpenralError: A file that does not load.
    """
    scene = load_scene(Path(sim_env_yaml)) if sim_env_yaml else None
    if manifest_path:
        robot = open_robot(Path(manifest_path))
        if robot_id and robot_id != robot.name:
            raise ValueError(
                f"parameter robot_id is {robot_id} but manifest_path {manifest_path} is "
                f"{robot.name}; set one of them"
            )
        return robot, scene
    if robot_id:
        return open_robot_by_id(robot_id), scene
    if scene is not None and scene.robot_id:
        return scene_robot(scene), scene
    raise ValueError(
        "no robot: set parameter robot_id or manifest_path, or a sim_env_yaml scene "
        "that names its robot_id"
    )


def real_options(
    calibration_file: str, arm_id: str, cameras: list[str], twin_scene: str = ""
) -> RealOptions:
    """The real driver's options from the parameters (the twin scene read once).

    Raises:
        ValueError: A ``cameras`` entry that is not ``NAME=DEVICE``.
        OpenralError: A twin scene file that does not load (located).
    """
    devices = {}
    for entry in (item for item in cameras if item):
        name, equals, device = entry.partition("=")
        if not equals or not name or not device:
            raise ValueError(f"parameter cameras: {entry!r} is not NAME=DEVICE (front=/dev/video0)")
        devices[name] = device
    return RealOptions(
        calibration_file=Path(calibration_file) if calibration_file else None,
        arm_id=arm_id or None,
        cameras=devices,
        twin_scene=load_scene(Path(twin_scene)) if twin_scene else None,
    )


def configured_hal(values: dict[str, Any]) -> tuple[LoadedRobot, RobotHal]:
    """The robot the parameters name and its HAL (not connected): a scene's is built
    without images in its observations (the sensor bridge renders each camera when due).

    Raises:
        ValueError, OpenralError: See :func:`robot_and_scene`, :func:`real_options` and
            ``build_hal``.
    """
    robot, scene = robot_and_scene(
        str(values["robot_id"]), str(values["manifest_path"]), str(values["sim_env_yaml"])
    )
    if values["twin_scene"] and values["hal_mode"] != "real":
        raise ValueError("parameter twin_scene is for a real robot (hal_mode real)")
    options = real_options(
        str(values["calibration_file"]),
        str(values["arm_id"]),
        list(values["cameras"]),
        str(values["twin_scene"]),
    )
    hal = build_hal(
        robot,
        mode=str(values["hal_mode"]),
        scene=scene,
        env_builder=_on_demand,
        transport=str(values["transport"]) or None,
        real_options=options,
    )
    return robot, hal


def _on_demand(scene: DeployScene, robot: LoadedRobot) -> SimRollout:
    return build_scene(scene, robot, render_observations=False)
