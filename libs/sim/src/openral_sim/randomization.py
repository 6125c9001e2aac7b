"""A native scene's declared randomisation, drawn from the episode's seed at every reset.

:class:`Randomizer` keeps the compiled model's own values (object colours, lights, fixed
cameras) and, at each reset, restores them and then draws, from
``numpy.random.default_rng(seed)`` in a fixed order:

1. per object of ``randomization.objects``: a position offset (uniform per axis between
   ``position_min_m`` and ``position_max_m``), a yaw about the world z axis, a colour;
2. one scale of every light's diffuse intensity, then a tilt of each directional light;
3. per fixed scene camera: a position offset and a turn about a random axis;
4. per arm joint: the start-pose noise.

So an episode depends on its seed only, never on the episodes before it or on the process.
A scene without ``randomization`` is left exactly as it was (whatever the seed).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from openral_core.models import DeployScene, Randomization
from openral_mujoco.state import FloatArray

AXES = 3


class Randomizer:
    """Applies one scene's ``randomization`` (see the module doc)."""

    def __init__(self, scene: DeployScene, model: mujoco.MjModel, cameras: list[str]) -> None:
        """Remember ``model``'s own values; ``cameras`` are the fixed scene cameras."""
        self.ranges: Randomization | None = scene.randomization
        self.model = model
        options = scene.scene.options
        self._objects = {o.name: o for o in (options.objects or [])} if options else {}
        self._rgba = model.geom_rgba.copy()
        self._light_diffuse = model.light_diffuse.copy()
        self._light_dir = model.light_dir.copy()
        self._cameras = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, c) for c in cameras]
        self._cam_pos = model.cam_pos.copy()
        self._cam_quat = model.cam_quat.copy()

    def apply(self, data: mujoco.MjData, seed: int | None, arm_qpos: np.ndarray) -> None:
        """Restore the model's values, then draw and apply this seed's episode (objects'
        free joints and arm joints in ``data``, the rest in the model)."""
        if self.ranges is None:
            return
        model = self.model
        model.geom_rgba[:] = self._rgba
        model.light_diffuse[:] = self._light_diffuse
        model.light_dir[:] = self._light_dir
        model.cam_pos[:] = self._cam_pos
        model.cam_quat[:] = self._cam_quat
        rng = np.random.default_rng(0 if seed is None else seed)
        for item in self.ranges.objects or []:
            self._object(
                data,
                rng,
                item.object,
                item.position_min_m,
                item.position_max_m,
                item.yaw_deg,
                item.rgba,
            )
        self._lights(rng)
        self._cameras_jitter(rng)
        if self.ranges.joint_noise:
            noise = self.ranges.joint_noise
            data.qpos[arm_qpos] += _between(rng, -noise, noise, len(arm_qpos))

    def _object(
        self,
        data: mujoco.MjData,
        rng: np.random.Generator,
        name: str,
        low: list[float] | None,
        high: list[float] | None,
        yaw_deg: list[float] | None,
        colours: list[list[float]] | None,
    ) -> None:
        model = self.model
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"scene_{name}")
        offset = np.zeros(AXES)
        if low is not None and high is not None:
            offset = _between(rng, np.asarray(low), np.asarray(high), AXES)
        yaw = math.radians(_one(rng, yaw_deg[0], yaw_deg[1])) if yaw_deg is not None else 0.0
        joint = int(model.body_jntadr[body])
        if joint >= 0 and model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
            adr = int(model.jnt_qposadr[joint])
            data.qpos[adr : adr + 3] = np.asarray(self._objects[name].position_m) + offset
            data.qpos[adr + 3 : adr + 7] = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
        if colours:
            geom = int(model.body_geomadr[body])
            model.geom_rgba[geom] = colours[int(rng.integers(len(colours)))]

    def _lights(self, rng: np.random.Generator) -> None:
        ranges = self.ranges
        assert ranges is not None
        if ranges.light_intensity_scale is not None:
            low, high = ranges.light_intensity_scale
            self.model.light_diffuse[:] = self._light_diffuse * _one(rng, low, high)
        if ranges.light_direction_deg:
            tilt = ranges.light_direction_deg
            for light in range(self.model.nlight):
                self.model.light_dir[light] = _tilted(self._light_dir[light], tilt, rng)

    def _cameras_jitter(self, rng: np.random.Generator) -> None:
        ranges = self.ranges
        assert ranges is not None
        for camera in self._cameras:
            if ranges.camera_position_m:
                step = ranges.camera_position_m
                offset = _between(rng, -step, step, AXES)
                self.model.cam_pos[camera] = self._cam_pos[camera] + offset
            if ranges.camera_angle_deg:
                turn = np.empty(4)
                axis = rng.normal(size=AXES)
                angle = math.radians(_one(rng, -ranges.camera_angle_deg, ranges.camera_angle_deg))
                mujoco.mju_axisAngle2Quat(turn, axis / np.linalg.norm(axis), angle)
                turned = np.empty(4)
                mujoco.mju_mulQuat(turned, turn, self._cam_quat[camera])
                self.model.cam_quat[camera] = turned


def _tilted(direction: FloatArray, max_deg: float, rng: np.random.Generator) -> FloatArray:
    """``direction`` turned by up to ``max_deg`` about a random axis (a unit vector)."""
    axis = rng.normal(size=AXES)
    axis -= axis.dot(direction) * direction / max(direction.dot(direction), 1e-12)
    norm = np.linalg.norm(axis)
    if norm < 1e-9:
        return direction.copy()
    turn = np.empty(4)
    mujoco.mju_axisAngle2Quat(turn, axis / norm, math.radians(_one(rng, 0.0, max_deg)))
    turned = np.empty(3)
    mujoco.mju_rotVecQuat(turned, direction, turn)
    return turned


def _between(
    rng: np.random.Generator, low: float | FloatArray, high: float | FloatArray, size: int
) -> FloatArray:
    """``size`` uniform draws between ``low`` and ``high`` (the very draws of
    ``rng.uniform``, which refuses a range the scene rules accept: 0.0 to -0.0)."""
    return np.asarray(low + (np.asarray(high) - low) * rng.random(size), dtype=np.float64)


def _one(rng: np.random.Generator, low: float, high: float) -> float:
    """One uniform draw between ``low`` and ``high`` (see :func:`_between`)."""
    return float(low + (high - low) * rng.random())
