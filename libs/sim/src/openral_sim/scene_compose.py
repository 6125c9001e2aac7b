"""How a native scene is composed with MjSpec: an empty world with the robot model's
physics options, floor, lights and sky, an optional table and pedestal, the scene's objects
(loose, or fixed to the world with ``free: false``), the robot attached at its base pose
(welded if asked; on its mobile base, see :mod:`openral_sim.scene_base`), the cameras and
the sensor sites (lidars, IMUs, force-torque and pose sensors) the manifest mounts on the
robot's bodies, and the MuJoCo sensors a state sensor asks for
(:mod:`openral_sim.state_sensors`). The robot's own file is edited as its manifest asks
(:func:`openral_sim.scene_base.robot_spec`: gravity compensation, lighter visual meshes).

Every fault is reported at its field of the scene file or the manifest.
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from openral_core.located import error_at
from openral_core.models import (
    DeployScene,
    DepthSensor,
    NativeAssets,
    RobotDescription,
    SceneObject,
)
from openral_mujoco.model_cache import cached_model, code_digest
from openral_mujoco.model_check import require_agreement
from openral_mujoco.robot_bodies import root_body

from openral_sim.camera_framing import place_fixed_cameras
from openral_sim.scene_base import (
    RobotModels,
    add_sensor_sites,
    attach_robot,
    robot_models,
    robot_spec,
)
from openral_sim.scene_cameras import add_fixed_cameras, add_mounted_cameras, rotate_about_z
from openral_sim.scene_checks import check_object_names, check_weld
from openral_sim.scene_geometry import BASE_WELD, lowest_static_point, yaw_quat
from openral_sim.scene_lighting import add_scene_lights, balance_lights
from openral_sim.state_sensors import add_state_sensors
from openral_sim.tcp_sensors import add_tcp_sensors

DEFAULT_TABLE_HEIGHT_M = 0.75
PHYSICS_OPTIONS = tuple(key for key in dir(mujoco.MjSpec().option) if not key.startswith("_"))
"""Every ``<option>`` of MjSpec (timestep, integrator, solver, tolerances, gravity, flags…)."""


@dataclass(frozen=True)
class ComposedScene:
    """The compiled scene, and the robot's own compiled model (where its wiring's addresses
    are taken)."""

    model: mujoco.MjModel
    robot_model: mujoco.MjModel


def compose(
    scene: DeployScene, robot: RobotDescription, folder: Path, cameras: dict[str, str]
) -> ComposedScene:
    """Compose and compile ``scene`` around ``robot`` (manifest in ``folder``), after checking
    the manifest against its model (and its mobile base's); the compiled models come from
    :mod:`~openral_mujoco.model_cache` when nothing they are made of has changed (every
    file of the robot's and the base's MJCF is part of the scene's key).

    Raises:
        ManifestError: At the scene file's or manifest's field that cannot be built.
    """
    assert robot.sim is not None
    check_weld(scene, robot)
    models = robot_models(robot, folder)
    require_agreement(robot, models.model, models.base_model)
    check_object_names(scene, models.model, models.base_model)
    fingerprints = models.fingerprints
    parts = None
    if fingerprints is not None:
        inputs = (scene.model_dump_json(), robot.model_dump_json(), json.dumps(cameras))
        parts = ("scene", *fingerprints, _composer_digest(), *inputs)
    model = cached_model(parts, lambda: _compile(scene, robot, models, cameras))
    return ComposedScene(model, models.model)


@functools.cache
def _composer_digest() -> str:
    """Digest of the code a composed scene depends on (this package and the MuJoCo layer)."""
    import openral_mujoco

    import openral_sim

    return code_digest(openral_sim, openral_mujoco)


def _compile(
    scene: DeployScene, robot: RobotDescription, models: RobotModels, cameras: dict[str, str]
) -> mujoco.MjModel:
    """Build the scene's spec (see the module doc) and compile it."""
    assert robot.sim is not None
    child, child_model = robot_spec(robot, models.path), models.model
    spec = _scene_spec(scene, robot, child)
    pose = scene.base_pose
    base = np.asarray(pose.position_m if pose and pose.position_m else [0.0, 0.0, 0.0])
    yaw = math.radians(pose.yaw_deg if pose and pose.yaw_deg else 0.0)
    own_floor = any(g.type == mujoco.mjtGeom.mjGEOM_PLANE for g in child.geoms)  # no 2nd
    floor_z = 0.0
    if robot.mobile_base is not None:  # the base stands on the floor where it is placed
        floor_z = float(base[2])
    elif scene.scene.assets is NativeAssets.floor:  # the model brings a table: floor under it
        floor_z = min(0.0, base[2] + lowest_static_point(child_model) - 0.001)
    own_sky = any(t.type == mujoco.mjtTexture.mjTEXTURE_SKYBOX for t in child.textures)
    _add_world(spec, floor_z=None if own_floor else floor_z, sky=not own_sky)
    if scene.scene.assets is NativeAssets.tabletop:
        fixed = robot.sim.floating_base is False and robot.mobile_base is None
        _add_tabletop(spec, scene, base, yaw, fixed=fixed)
    options = scene.scene.options
    for obj in options.objects if options and options.objects else []:
        _add_object(spec, obj)
    frame = spec.worldbody.add_frame(pos=base.tolist(), quat=yaw_quat(yaw).tolist())
    attach_robot(spec, child, robot, models, frame)
    balance_lights(spec)
    add_mounted_cameras(spec, robot, cameras)
    add_sensor_sites(spec, robot)
    add_state_sensors(spec, robot)
    add_tcp_sensors(spec, robot, child_model)
    if pose is not None and pose.weld:
        _add_base_weld(spec, child_model, robot)
    add_fixed_cameras(spec, robot, cameras)
    try:
        model = spec.compile()
    except ValueError as error:
        message = f"scene {scene.scene.id!r} for {robot.name!r} does not compile: {error}"
        raise error_at(scene, ("scene",), message) from None
    place_fixed_cameras(model, scene, robot, cameras)
    return model


def _add_tabletop(
    spec: mujoco.MjSpec, scene: DeployScene, base: np.ndarray, yaw: float, *, fixed: bool
) -> None:
    """The table, and a pedestal under a fixed base raised above the floor."""
    options = scene.scene.options
    table_h = (
        options.table_height_m
        if options and options.table_height_m is not None
        else DEFAULT_TABLE_HEIGHT_M
    )
    _add_table(spec, base, yaw, table_h)
    if fixed and base[2] > 0.05:
        spec.worldbody.add_geom(
            name="scene_pedestal",
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=[0.09, base[2] / 2, 0],
            pos=[base[0], base[1], base[2] / 2],
            rgba=[0.3, 0.3, 0.32, 1],
        )


def _scene_spec(scene: DeployScene, robot: RobotDescription, child: mujoco.MjSpec) -> mujoco.MjSpec:
    """An empty world with every physics option of the robot's model (so the robot moves as
    it does alone) and an offscreen buffer for the scene's images (no shadows or
    multisampling: they cost more than they show at 128 px)."""
    spec = mujoco.MjSpec()
    spec.modelname = f"{scene.scene.id}_{robot.name}"
    for key in PHYSICS_OPTIONS:
        setattr(spec.option, key, getattr(child.option, key))
    spec.compiler.degree = False
    width, height = scene.scene.observation.width, scene.scene.observation.height
    depth = [s for s in robot.sensors if isinstance(s, DepthSensor)]
    depth = [s for s in depth if s.name in scene.scene.cameras]  # each at its own size
    spec.visual.global_.offwidth = max([width, 640, *(s.width for s in depth)])
    spec.visual.global_.offheight = max([height, 480, *(s.height for s in depth)])
    spec.visual.quality.shadowsize = 0
    spec.visual.quality.offsamples = 0
    return spec


def _add_base_weld(
    spec: mujoco.MjSpec, child_model: mujoco.MjModel, robot: RobotDescription
) -> None:
    """A weld holding the floating root body; its pose is set at every reset."""
    assert robot.sim is not None and robot.sim.floating_base, "_compose checks the base"
    root = root_body(child_model, robot)
    timestep = spec.option.timestep
    spec.add_equality(
        name=BASE_WELD,
        type=mujoco.mjtEq.mjEQ_WELD,
        objtype=mujoco.mjtObj.mjOBJ_BODY,
        name1=mujoco.mj_id2name(child_model, mujoco.mjtObj.mjOBJ_BODY, root),
        solref=[2 * timestep, 1.0],  # as stiff as the time step allows
    )


def _add_world(spec: mujoco.MjSpec, *, floor_z: float | None, sky: bool) -> None:
    add_scene_lights(spec)
    if sky:  # a camera looking up or away sees a sky, not black
        spec.add_texture(
            name="scene_sky",
            type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
            builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
            rgb1=[0.62, 0.72, 0.82],
            rgb2=[0.16, 0.18, 0.22],
            width=256,
            height=256,
        )
    if floor_z is None:
        return
    spec.worldbody.add_geom(
        pos=[0.0, 0.0, floor_z],
        name="scene_floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[5, 5, 0.05],
        rgba=[0.55, 0.6, 0.65, 1],
    )


def _add_table(spec: mujoco.MjSpec, base: np.ndarray, yaw: float, height: float) -> None:
    centre = base + rotate_about_z(yaw, np.array([0.55, 0.0, 0.0]))
    spec.worldbody.add_geom(
        name="scene_table",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.4, 0.6, height / 2],
        pos=[centre[0], centre[1], height / 2],
        quat=yaw_quat(yaw).tolist(),
        rgba=[0.72, 0.55, 0.38, 1],
    )


EVERY_GROUP = 0xFFFF
"""``conaffinity`` of a scene object: it touches every collision geom of the robot, whatever
collision group (``contype`` bit) the robot's model puts it in."""


def _add_object(spec: mujoco.MjSpec, obj: SceneObject) -> None:
    shapes = {
        "box": mujoco.mjtGeom.mjGEOM_BOX,
        "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
        "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    }
    size = [*obj.size_m, 0.0, 0.0][:3]
    body = spec.worldbody.add_body(name=f"scene_{obj.name}", pos=list(obj.position_m))
    if obj.free is not False:  # free: false is a static body (a wall, a table)
        body.add_freejoint(name=f"scene_{obj.name}_joint")
    body.add_geom(
        name=f"scene_{obj.name}_geom",
        type=shapes[obj.shape],
        size=size,
        rgba=list(obj.rgba or [0.8, 0.2, 0.2, 1.0]),
        mass=obj.mass_kg or 0.1,
        conaffinity=EVERY_GROUP,
    )
