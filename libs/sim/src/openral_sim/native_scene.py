"""The native scene backend: any manifest's robot composed into a tabletop with MjSpec.

The scene adds a floor, lights, optionally a table and a pedestal, the objects the scene file
lists, and a camera for every manifest camera sensor the scene file names (placed as
:mod:`openral_sim.scene_cameras` says). Before composing, the manifest is checked against
the robot's own model (:func:`~openral_mujoco.model_check.require_agreement`); every fault of
the scene file or the manifest is reported at its field's line and column.

The action is one control value per actuator of the robot model. For a ``torque_pd`` robot
the values are position targets, turned into torques by the manifest's PD law every step.
The hold action (what an idle scene is stepped with) is the current targets, so an idle
robot stays where it was last sent.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError
from openral_core.located import error_at
from openral_core.models import DeployScene, RobotDescription
from openral_core.tables import hal_wiring, joint_name_map
from openral_mujoco.control_law import pd_torque, seed_position_servos
from openral_mujoco.mjcf_model import ctrl_limits
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import require_agreement, unloadable_model

from openral_sim.rollout import Observation, StepResult
from openral_sim.scene_cameras import (
    add_fixed_cameras,
    add_mounted_cameras,
    camera_sensors,
    rotate_about_z,
)
from openral_sim.scene_checks import check_object_names, check_weld, physics_steps_per_control
from openral_sim.scene_geometry import lowest_static_point, robot_extent, root_body

ASSETS = ("tabletop", "floor")
"""``scene.assets`` values: a table in front of the robot, or only floor and lights (for
models that bring their own table)."""
DEFAULT_TABLE_HEIGHT_M = 0.75
BASE_WELD = "scene_base_weld"
"""Name of the equality constraint that holds a welded floating base."""


class SceneError(OpenralError):
    """A scene file that cannot be built for its robot."""


class NativeScene:
    """A MuJoCo scene composed from a manifest and a deploy-scene file (a SimRollout)."""

    def __init__(self, scene: DeployScene, robot: RobotDescription):
        """Compose ``scene`` around ``robot`` (both as loaded, so errors point into them).

        Raises:
            ManifestError: At the field of the scene file or manifest that cannot be built:
                an unknown asset or camera, a manifest that disagrees with its model, an
                object name the model already uses, a weld on a fixed base, a control rate
                the model's physics step cannot serve.
        """
        self.scene = scene
        self.robot = robot
        if scene.scene.assets not in ASSETS:
            message = f"{scene.scene.assets!r} is not a native scene; expected one of {ASSETS}"
            raise error_at(scene, ("scene", "assets"), message)
        if robot.sim is None:
            raise error_at(scene, ("robot_id",), f"robot {robot.name!r} has no sim block")
        self._sensors = camera_sensors(scene, robot)
        self.model = _compose(scene, robot, self._sensors)
        self.data = mujoco.MjData(self.model)
        wiring = hal_wiring(robot)
        assert wiring is not None
        self._keyframe = wiring.keyframe_index
        self._floating = wiring.floating_base
        self._root_body = root_body(self.model, robot)
        self._root_qpos = int(self.model.jnt_qposadr[self.model.body_jntadr[self._root_body]])
        self._width = scene.scene.observation.width
        self._height = scene.scene.observation.height
        options = scene.scene.options
        self.substeps = physics_steps_per_control(scene, self.model.opt.timestep)
        self.horizon = options.horizon if options and options.horizon else None
        self._ctrl_low, self._ctrl_high = ctrl_limits(self.model)
        self._pd = _pd_law(robot, self.model) if wiring.control_mode == "torque_pd" else None
        self._targets = np.zeros(self.model.nu)
        self._renderer: mujoco.Renderer | None = None
        self._steps = 0

    # -- SimRollout ------------------------------------------------------------------------

    @property
    def action_dim(self) -> int:
        """One value per actuator of the robot model."""
        return int(self.model.nu)

    @property
    def action_names(self) -> tuple[str, ...]:
        """The actuator names of the model (``actuator[i]`` for an unnamed one)."""
        names = (
            mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, i)
            for i in range(self.model.nu)
        )
        return tuple(name or f"actuator[{i}]" for i, name in enumerate(names))

    def hold_action(self) -> npt.NDArray[np.float64]:
        """The targets in force now (the start pose after a reset)."""
        return self._targets.copy()

    @property
    def camera_names(self) -> tuple[str, ...]:
        """Manifest sensor names rendered into ``obs["images"]``."""
        return tuple(self._sensors)

    @property
    def camera_models(self) -> dict[str, str]:
        """Sensor name → MJCF camera of the composed model."""
        return dict(self._sensors)

    def reset(self, seed: int | None = None) -> Observation:
        """Keyframe (if any) at the scene's base pose, actuators holding the start pose.

        The native scene has nothing random in it; ``seed`` is accepted for the protocol.
        """
        mujoco.mj_resetData(self.model, self.data)
        if self._keyframe is not None:
            mujoco.mj_resetDataKeyframe(self.model, self.data, self._keyframe)
            if self._floating:
                self._place_floating_base()
        self._hold_base_where_it_is()
        seed_position_servos(self.model, self.data)  # nothing jumps at start
        mujoco.mj_forward(self.model, self.data)
        if self._pd is not None:  # targets are joint positions: hold the current ones
            joints = self.model.actuator_trnid[:, 0]
            self.data.ctrl[:] = self.data.qpos[self.model.jnt_qposadr[joints]]
        self._targets = self.data.ctrl.astype(np.float64)
        self._steps = 0
        return self._observe()

    def step(self, action: npt.NDArray[Any]) -> StepResult:
        """Apply ``action`` (one value per actuator) for one control period."""
        values = np.asarray(action, dtype=np.float64)
        if values.shape != (self.action_dim,):
            raise SceneError(f"action has shape {values.shape}; expected ({self.action_dim},)")
        if self._pd is None:
            self._targets = np.clip(values, self._ctrl_low, self._ctrl_high)
            self.data.ctrl[:] = self._targets
            mujoco.mj_step(self.model, self.data, nstep=self.substeps)
        else:
            self._targets = values.copy()
            for _ in range(self.substeps):
                self.data.ctrl[:] = self._pd(self.data, values)
                mujoco.mj_step(self.model, self.data)
        self._steps += 1
        truncated = self.horizon is not None and self._steps >= self.horizon
        return StepResult(self._observe(), truncated=truncated, info={"steps": self._steps})

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """The scene's live (model, data)."""
        return self.model, self.data

    def close(self) -> None:
        """Free the offscreen renderer."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # -- internals -------------------------------------------------------------------------

    def _observe(self) -> Observation:
        if self._sensors and self._renderer is None:
            self._renderer = mujoco.Renderer(self.model, self._height, self._width)
        images: dict[str, npt.NDArray[np.uint8]] = {}
        for sensor, camera in self._sensors.items():
            assert self._renderer is not None
            self._renderer.update_scene(self.data, camera=camera)
            images[sensor] = self._renderer.render().copy()
        return {"images": images, "time": float(self.data.time)}

    def _hold_base_where_it_is(self) -> None:
        """Aim the base weld (if any) at the root body's pose now: relpose is the world's
        pose in the root body's frame."""
        weld = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_EQUALITY, BASE_WELD)
        if weld < 0:
            return
        mujoco.mj_kinematics(self.model, self.data)
        body = self._root_body
        inverse = np.empty(4)
        mujoco.mju_negQuat(inverse, self.data.xquat[body])
        position = np.empty(3)
        mujoco.mju_rotVecQuat(position, -self.data.xpos[body], inverse)
        self.model.eq_data[weld, 0:3] = 0.0
        self.model.eq_data[weld, 3:6] = position
        self.model.eq_data[weld, 6:10] = inverse

    def _place_floating_base(self) -> None:
        """Keyframe free-joint poses are world poses: move them to the scene's base pose."""
        pose = self.scene.base_pose
        if pose is None:
            return
        position = np.asarray(pose.position_m or [0.0, 0.0, 0.0])
        yaw = math.radians(pose.yaw_deg or 0.0)
        free = self._root_qpos  # the robot's free joint (objects may have their own)
        self.data.qpos[free : free + 3] += position
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, _yaw_quat(yaw), self.data.qpos[free + 3 : free + 7].copy())
        self.data.qpos[free + 3 : free + 7] = quat


def _robot_spec(robot: RobotDescription) -> tuple[mujoco.MjSpec, mujoco.MjModel]:
    """The robot's own model as a spec to attach, and compiled, checked against its manifest.

    Raises:
        ManifestError: At ``sim.mjcf_uri`` or at every manifest field the model contradicts.
    """
    path = robot_model_file(robot)  # next to the manifest it was loaded from
    try:
        child = mujoco.MjSpec.from_file(str(path))
        child_model = child.copy().compile()  # before attach: no compile after it
    except ValueError as error:
        raise unloadable_model(robot, path, error) from None
    require_agreement(robot, child_model)
    return child, child_model


def _compose(
    scene: DeployScene, robot: RobotDescription, cameras: dict[str, str]
) -> mujoco.MjModel:
    assert robot.sim is not None
    check_weld(scene, robot)
    child, child_model = _robot_spec(robot)
    check_object_names(scene, child_model)
    spec = _scene_spec(scene, robot, child)
    pose = scene.base_pose
    base = np.asarray(pose.position_m if pose and pose.position_m else [0.0, 0.0, 0.0])
    yaw = math.radians(pose.yaw_deg if pose and pose.yaw_deg else 0.0)
    options = scene.scene.options
    own_floor = any(g.type == mujoco.mjtGeom.mjGEOM_PLANE for g in child.geoms)  # no 2nd
    floor_z = 0.0
    if scene.scene.assets == "floor":  # the model brings a table: the floor goes under it
        floor_z = min(0.0, base[2] + lowest_static_point(child_model) - 0.001)
    own_sky = any(t.type == mujoco.mjtTexture.mjTEXTURE_SKYBOX for t in child.textures)
    _add_world(spec, floor_z=None if own_floor else floor_z, sky=not own_sky)
    if scene.scene.assets == "tabletop":
        table_h = (
            options.table_height_m
            if options and options.table_height_m is not None
            else DEFAULT_TABLE_HEIGHT_M
        )
        _add_table(spec, base, yaw, table_h)
        fixed = robot.sim.floating_base is False
        if fixed and base[2] > 0.05:
            spec.worldbody.add_geom(
                name="scene_pedestal",
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                size=[0.09, base[2] / 2, 0],
                pos=[base[0], base[1], base[2] / 2],
                rgba=[0.3, 0.3, 0.32, 1],
            )
    for obj in options.objects if options and options.objects else []:
        _add_object(spec, obj)
    frame = spec.worldbody.add_frame(pos=base.tolist(), quat=_yaw_quat(yaw).tolist())
    center, radius = robot_extent(child_model, robot)
    add_mounted_cameras(child, robot, cameras)
    spec.attach(child, frame=frame, prefix="")
    if pose is not None and pose.weld:
        _add_base_weld(spec, child_model, robot)
    add_fixed_cameras(spec, robot, cameras, base + rotate_about_z(yaw, center), yaw, radius)
    try:
        return spec.compile()
    except ValueError as error:
        message = f"scene {scene.scene.id!r} for {robot.name!r} does not compile: {error}"
        raise error_at(scene, ("scene",), message) from None


def _scene_spec(scene: DeployScene, robot: RobotDescription, child: mujoco.MjSpec) -> mujoco.MjSpec:
    """An empty world with the robot model's physics options and an offscreen buffer for the
    scene's images (no shadows or multisampling: they cost more than they show at 128 px)."""
    spec = mujoco.MjSpec()
    spec.modelname = f"{scene.scene.id}_{robot.name}"
    for key in ("timestep", "integrator", "cone", "impratio", "noslip_iterations"):
        setattr(spec.option, key, getattr(child.option, key))
    spec.compiler.degree = False
    width, height = scene.scene.observation.width, scene.scene.observation.height
    spec.visual.global_.offwidth = max(width, 640)
    spec.visual.global_.offheight = max(height, 480)
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
    spec.worldbody.add_light(name="scene_key_light", pos=[0.5, -1.0, 3.0], dir=[0, 0.3, -1])
    spec.worldbody.add_light(name="scene_fill_light", pos=[-1.0, 1.0, 2.5], dir=[0.4, -0.3, -1])
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
        quat=_yaw_quat(yaw).tolist(),
        rgba=[0.72, 0.55, 0.38, 1],
    )


def _add_object(spec: mujoco.MjSpec, obj: Any) -> None:
    shapes = {
        "box": mujoco.mjtGeom.mjGEOM_BOX,
        "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
        "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    }
    size = [*obj.size_m, 0.0, 0.0][:3]
    body = spec.worldbody.add_body(name=f"scene_{obj.name}", pos=list(obj.position_m))
    body.add_freejoint(name=f"scene_{obj.name}_joint")
    body.add_geom(
        name=f"scene_{obj.name}_geom",
        type=shapes[obj.shape],
        size=size,
        rgba=list(obj.rgba or [0.8, 0.2, 0.2, 1.0]),
        mass=obj.mass_kg or 0.1,
    )


def _pd_law(robot: RobotDescription, model: mujoco.MjModel) -> Any:
    """The manifest's PD law (:func:`pd_torque`) for every actuator, as a function of the
    data and the per-actuator position targets."""
    wiring = hal_wiring(robot)
    assert wiring is not None
    canonical = {mjcf: name for name, mjcf in joint_name_map(robot).items()}
    joints = model.actuator_trnid[:, 0]
    qpos_addr = model.jnt_qposadr[joints]
    dof_addr = model.jnt_dofadr[joints]
    names = [
        canonical.get(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "", "")
        for j in joints
    ]
    kp = np.array([wiring.kp.get(n, 0.0) for n in names])
    kd = np.array([wiring.kd.get(n, 0.0) for n in names])
    low, high = ctrl_limits(model)

    def law(data: mujoco.MjData, targets: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        return pd_torque(kp, kd, targets, data.qpos[qpos_addr], data.qvel[dof_addr], low, high)

    return law


def _yaw_quat(yaw: float) -> npt.NDArray[np.float64]:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
