"""The robot's place in a native scene: its own model alone, or on its mobile base.

A robot with a ``mobile_base`` is two models: the base's, attached to the world at the
scene's base pose (the base stands on the floor: its frame is on its floor plane), and the
robot's, attached to the base's ``mount_body`` at the mount offset. In the composed model
the base is the root of the robot's tree, so :func:`~openral_sim.scene_geometry.root_body`
and :func:`~openral_sim.scene_geometry.robot_bodies` see base and robot as one robot; the
robot's own compiled model stays the robot alone, so its wiring's addresses keep their
meaning (:func:`~openral_mujoco.robot_addresses.locate_robot` finds them again by name).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
from openral_core.loaded import LoadedRobot
from openral_core.located import error_at
from openral_core.models import RobotDescription, SiteSensor
from openral_core.tables import mobile_base_wiring
from openral_mujoco.errors import HalError
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.mobile_base import base_model_file, base_spec, cached_base_model
from openral_mujoco.model_cache import cached_model
from openral_mujoco.model_check import cached_robot_model, require_agreement, unloadable_model
from openral_mujoco.robot_addresses import RobotAddresses, locate_robot
from openral_mujoco.robot_edits import edit_robot_spec, robot_cache_kind


@dataclass(frozen=True)
class RobotModels:
    """The robot's model file and compiled model, its mobile base's (None without one), and
    the model-cache fingerprints of every file they read (None: a file list that could not
    be made, then nothing is cached)."""

    path: Path
    model: mujoco.MjModel
    base_path: Path | None
    base_model: mujoco.MjModel | None
    fingerprints: tuple[str, ...] | None


def robot_models(robot: RobotDescription, folder: Path) -> RobotModels:
    """Resolve and compile (or load from the model cache) the robot's and its base's models.

    Raises:
        ManifestError: At ``sim.mjcf_uri`` or ``mobile_base.mjcf_uri``.
    """
    path = robot_model_file(robot, folder)
    model, fingerprint = cached_robot_model(robot, path)
    if robot.mobile_base is None:
        return RobotModels(path, model, None, None, _known(fingerprint))
    base_path = base_model_file(robot, folder)
    base_model, base_fingerprint = cached_base_model(robot, base_path)
    prints = _known(fingerprint, base_fingerprint)
    return RobotModels(path, model, base_path, base_model, prints)


def _known(*fingerprints: str | None) -> tuple[str, ...] | None:
    """All of ``fingerprints``, or None when one is unknown."""
    known = tuple(f for f in fingerprints if f is not None)
    return known if len(known) == len(fingerprints) else None


def attach_robot(
    spec: mujoco.MjSpec,
    child: mujoco.MjSpec,
    robot: RobotDescription,
    models: RobotModels,
    frame: mujoco.MjsFrame,
) -> None:
    """Attach the robot's spec ``child`` to ``spec`` at the world ``frame`` (the base pose):
    directly, or on its mobile base, which is attached there instead."""
    wiring = mobile_base_wiring(robot)
    if wiring is None or models.base_path is None:
        spec.attach(child, frame=frame, prefix="")
        return
    spec.attach(base_spec(robot, models.base_path), frame=frame, prefix="")
    mount = spec.body(wiring.mount_body)
    assert mount is not None, "require_agreement checks the mount body before composing"
    on_base = mount.add_frame(pos=list(wiring.mount_position_m), quat=list(wiring.mount_quat_wxyz))
    spec.attach(child, frame=on_base, prefix="")


def add_sensor_sites(spec: mujoco.MjSpec, robot: RobotDescription) -> None:
    """A site for each lidar, IMU, force-torque or pose sensor with a ``mount_body``, at its
    ``mount_position_m`` with the body's axes (a lidar's scan plane is the body's x-y
    plane)."""
    for sensor in robot.sensors:
        if not isinstance(sensor, SiteSensor) or sensor.mount_body is None:
            continue
        body = spec.body(sensor.mount_body)
        assert body is not None, "require_agreement checks mount bodies before composing"
        body.add_site(name=sensor.site, pos=list(sensor.mount_position_m or [0.0, 0.0, 0.0]))


@dataclass(frozen=True)
class RobotAlone:
    """The robot by itself (on its mobile base, if it has one) at the world's origin: the
    model its URDF is read from, and where its joints and actuators are in it."""

    model: mujoco.MjModel
    addresses: RobotAddresses


def robot_alone(robot: LoadedRobot) -> RobotAlone:
    """Compile (or load from the model cache) the robot with its mobile base and nothing
    else, as :func:`attach_robot` composes them in a scene.

    Raises:
        ManifestError: At ``sim.mjcf_uri`` or ``mobile_base.mjcf_uri``, or when the manifest
            disagrees with its model.
    """
    description, wiring = robot.description, robot.tables.hal_wiring
    if wiring is None:
        raise error_at(description, ("name",), f"robot {robot.name!r} has no sim block")
    models = robot_models(description, robot.folder)
    require_agreement(description, models.model, models.base_model)
    model = models.model
    if models.base_path is not None:
        parts = None
        if models.fingerprints is not None:
            kind = robot_cache_kind(description)
            parts = ("robot-alone", kind, *models.fingerprints, description.model_dump_json())
        model = cached_model(parts, lambda: _alone(description, models))
    try:
        addresses = locate_robot(wiring, models.model, model)
    except HalError as error:
        raise error_at(description, ("joints",), str(error)) from None
    return RobotAlone(model, addresses)


def _alone(robot: RobotDescription, models: RobotModels) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    child = robot_spec(robot, models.path)
    attach_robot(spec, child, robot, models, spec.worldbody.add_frame())
    return spec.compile()


def robot_spec(robot: RobotDescription, path: Path) -> mujoco.MjSpec:
    """The robot's own model at ``path`` as a spec to attach, edited as its manifest asks.

    Raises:
        ManifestError: At ``sim.mjcf_uri`` when MuJoCo cannot read the file, or at
            ``sim.visual_mesh_faces`` (:func:`~openral_mujoco.robot_edits.edit_robot_spec`).
    """
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as error:
        raise unloadable_model(robot, path, error) from None
    return edit_robot_spec(spec, robot)
