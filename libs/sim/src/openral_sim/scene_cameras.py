"""Where a native scene's cameras come from and how they are placed.

- a sensor with ``camera`` renders that camera of the robot's own model;
- a sensor with ``mount_body`` gets a camera fixed to that body, looking forward (+x) on a
  torso, head, pelvis or base body and along the body's +z (the tool axis) on any other, or
  along the ``mount_axis`` the manifest names;
- any other sensor is a fixed camera in front of the robot that shows all of it and the
  objects around it (:mod:`openral_sim.camera_framing`).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.located import error_at
from openral_core.models import DeployScene, DepthSensor, RgbSensor, RobotDescription

FORWARD_LOOKING = ("torso", "head", "pelvis", "base")
"""Body names (substrings) a mounted camera looks forward (+x) from by default."""


def camera_sensors(scene: DeployScene, robot: RobotDescription) -> dict[str, str]:
    """Scene camera list → {sensor name: MJCF camera name}, in the scene file's order.

    Raises:
        ManifestError: At ``scene.cameras[i]`` for a name that is no camera sensor of the
            robot.
    """
    by_name = {s.name: s for s in robot.sensors if isinstance(s, RgbSensor | DepthSensor)}
    cameras: dict[str, str] = {}
    for index, name in enumerate(scene.scene.cameras):
        sensor = by_name.get(name)
        if sensor is None:
            known = ", ".join(by_name) or "(none)"
            message = (
                f"{name!r} is not a camera sensor of robot {robot.name!r}; its camera "
                f"sensors are: {known}"
            )
            raise error_at(scene, ("scene", "cameras", index), message)
        cameras[name] = sensor.camera or f"openral_{name}"
    return cameras


def add_mounted_cameras(
    spec: mujoco.MjSpec, robot: RobotDescription, cameras: dict[str, str]
) -> None:
    """A camera on each mounted sensor's body in ``spec`` (the robot's, and its mobile
    base's, are attached to it and were checked to have the body), at ``mount_position_m``
    when the manifest gives one."""
    for sensor in robot.sensors:
        if not isinstance(sensor, RgbSensor | DepthSensor) or sensor.name not in cameras:
            continue
        if sensor.camera is not None or sensor.mount_body is None:
            continue
        body = spec.body(sensor.mount_body)
        assert body is not None, "require_agreement checks mount bodies before composing"
        forward = any(word in sensor.mount_body.lower() for word in FORWARD_LOOKING)
        axis = sensor.mount_axis.value if sensor.mount_axis is not None else None
        # A MuJoCo camera looks along its -z axis with +y up.
        if axis is None and forward:  # along body +x, slightly down, from above the origin
            pos, xyaxes = [0.1, 0.0, 0.35], [0, -1, 0, 0.45, 0, 1]
        else:
            pos, xyaxes = looking_along(axis or "+z")
        if sensor.mount_position_m is not None:
            pos = list(sensor.mount_position_m)
        body.add_camera(
            name=cameras[sensor.name], pos=pos, xyaxes=xyaxes, fovy=sensor.fovy_deg or 60.0
        )


def looking_along(axis: str) -> tuple[list[float], list[float]]:
    """Camera position and xyaxes in a body's frame that look along body ``axis`` (e.g.
    ``+y``) from 7 cm beside it, image up pointing to that side (for ``+z``: from -y)."""
    index = "xyz".index(axis[1])
    look = np.zeros(3)
    look[index] = 1.0 if axis[0] == "+" else -1.0
    up = np.zeros(3)
    up[(index - 1) % 3] = -1.0  # z -> -y, y -> -x, x -> -z
    right = np.cross(up, -look)
    return (0.07 * up).tolist(), [*right.tolist(), *up.tolist()]


def add_fixed_cameras(
    spec: mujoco.MjSpec, robot: RobotDescription, cameras: dict[str, str]
) -> None:
    """A world camera for each sensor that names neither a model camera nor a mount body,
    with the sensor's field of view (default 45 degrees); where it stands is set once the
    scene is compiled (:func:`openral_sim.camera_framing.place_fixed_cameras`)."""
    for sensor in robot.sensors:
        if not isinstance(sensor, RgbSensor | DepthSensor) or sensor.name not in cameras:
            continue
        if sensor.camera is None and sensor.mount_body is None:
            spec.worldbody.add_camera(name=cameras[sensor.name], fovy=sensor.fovy_deg or 45.0)


def rotate_about_z(yaw: float, vector: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """``vector`` rotated by ``yaw`` [rad] about the world z axis."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1], vector[2]])
