"""SimAttachedHAL: a HAL that drives a scene it does not own the physics of.

Under ``deploy sim`` with a scene file, the scene backend (a :class:`SimRollout`) owns
physics and pixels; this HAL is the robot-side view of it. Every action is one ``env.step``
and camera frames come from the last observation. A native scene drives its robot by the
manifest's contract (:class:`~openral_sim.rollout.ManifestRollout`): then the action is one
value per manifest joint and the joint state is the scene's own, in manifest units. Another
backend (robosuite) keeps its controller's action; its joint state is read from the MuJoCo
data by joint name (or from ``obs["joint_positions"]`` for a non-MuJoCo backend).
The deploy control loop advances the scene one step per control period with
:meth:`SimAttachedHAL.tick`, which exists only on simulated HALs. A robot on a mobile base
in a native scene also takes base velocity commands (:meth:`SimAttachedHAL.command_base`,
refused while E-stopped; the E-stop halts the base) and reports odometry.
"""

from __future__ import annotations

import logging
import time
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.located import error_at
from openral_core.models import RgbSensor, RobotDescription
from openral_mujoco.action import validated_action
from openral_mujoco.mjcf_model import is_scalar_joint
from openral_mujoco.name_resolution import resolve_joint_names
from openral_mujoco.state import FloatArray, JointStateSample
from openral_sim.base_drive import BaseCommand, BaseDrive, BaseOdometry
from openral_sim.native_scene import NativeScene
from openral_sim.rollout import (
    HoldingRollout,
    ManifestRollout,
    Observation,
    SimRollout,
    StepResult,
)

from openral_hal.errors import ConfigurationError, HalError, NotConnected
from openral_hal.protocol import EStopLatch

_log = logging.getLogger(__name__)


class SimAttachedHAL(EStopLatch):
    """A robot inside a simulated scene; one action is one step of the scene.

    The action is the scene's own action (``action_dim`` values): one per manifest joint on
    a native scene, whatever its controller takes on robosuite.
    """

    is_real = False
    """A simulation, never real hardware."""

    def __init__(
        self,
        env: SimRollout,
        robot: LoadedRobot,
        *,
        env_reset_seed: int | None = 0,
        env_action_dim: int | None = None,
    ) -> None:
        """Attach to ``env``; nothing is reset until :meth:`connect`.

        Args:
            env: The scene backend.
            robot: The loaded robot (manifest: joint order, names and sensors; tables).
            env_reset_seed: Seed of every episode reset (None: the backend's own choice).
            env_action_dim: Action width, for a backend that does not report ``action_dim``.
        """
        self.env = env
        # checked once: a runtime Protocol check costs ~17 us, too much for every tick
        self._manifest_env = env if isinstance(env, ManifestRollout) else None
        self.robot = robot
        description = robot.description
        self.env_reset_seed = env_reset_seed
        self.env_action_dim = env_action_dim
        self.joint_names = tuple(j.name for j in description.joints)
        self._mjcf_names = tuple(robot.tables.joint_name_map[n] for n in self.joint_names)
        self._rgb = tuple(s.name for s in description.sensors if isinstance(s, RgbSensor))
        self._action_dim: int | None = None
        self._action_names: tuple[str, ...] = ()
        self._obs: Observation | None = None
        self._last_env_action: FloatArray = np.zeros(0)
        self._episode_done = False
        self._closed = False
        self._addr_model: mujoco.MjModel | None = None
        self._qpos = self._dof = np.zeros(0, dtype=np.intp)
        self._warned_width = False

    @property
    def description(self) -> RobotDescription:
        """The manifest of the attached robot."""
        return self.robot.description

    # -- lifecycle -------------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        """True between :meth:`connect` and :meth:`disconnect`."""
        return self._obs is not None

    @property
    def action_dim(self) -> int:
        """Width of the scene's action."""
        if self._action_dim is None:
            raise NotConnected("the HAL is not connected; call connect() first")
        return self._action_dim

    def connect(self) -> None:
        """Resolve the action width, reset the scene and find every manifest joint in it.

        Raises:
            ConfigurationError: The action width is unknown (the backend reports none and
                no ``env_action_dim`` was given) or not positive.
            HalError: A manifest joint is missing from the scene's model.
        """
        if self._closed:
            raise HalError("the scene was closed by disconnect(); build a new HAL")
        width = self.env_action_dim if self.env_action_dim is not None else self.env.action_dim
        if width is None:
            raise ConfigurationError(
                f"{type(self.env).__name__} does not report action_dim and no env_action_dim "
                "was given; cannot tell how wide an action must be"
            )
        if width < 1:
            raise ConfigurationError(f"{type(self.env).__name__}: action width {width} < 1")
        obs = self.env.reset(seed=self.env_reset_seed)
        handles = self.env.mujoco_handles()
        if handles is not None and self._manifest_env is None:
            self._resolve_addresses(handles[0])
        self._action_dim = width
        self._action_names = self._slot_names(width)
        self._last_env_action = np.zeros(width)
        self._episode_done = False
        self._obs = obs

    @property
    def action_names(self) -> tuple[str, ...]:
        """One name per action slot: the backend's, else the manifest joints when the widths
        agree, else ``env_action[i]`` (empty until :meth:`connect` learns the width)."""
        return self._action_names

    def hold_action(self) -> FloatArray:
        """The action that keeps the robot still: the backend's hold, else zeros.

        Zeros hold velocity and delta controllers; a position-controlled backend provides its
        current targets instead (zeros would send every joint towards 0 rad).
        """
        width = self.action_dim
        if isinstance(self.env, HoldingRollout):
            hold = np.asarray(self.env.hold_action(), dtype=np.float64).ravel()
            if hold.size == width:
                return hold
        return np.zeros(width)

    def disconnect(self) -> None:
        """Close the scene (renderers and all); the HAL cannot be connected again."""
        if not self._closed:
            self.env.close()
            self._closed = True
        self._obs = None
        self._action_dim = None
        self._action_names = ()

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        """The scene's live MuJoCo (model, data), or None for a non-MuJoCo backend."""
        return self.env.mujoco_handles()

    def camera_fovy_deg(self, sensor: str) -> float | None:
        """Vertical field of view of the scene camera that renders ``sensor`` (None when the
        backend has no MuJoCo model or does not render it)."""
        handles = self.env.mujoco_handles()
        camera = self.env.camera_models.get(sensor)
        if handles is None or camera is None:
            return None
        index = mujoco.mj_name2id(handles[0], mujoco.mjtObj.mjOBJ_CAMERA, camera)
        return float(handles[0].cam_fovy[index]) if index >= 0 else None

    # -- state and sensors -----------------------------------------------------------------

    def read_state(self) -> JointStateSample:
        """Every manifest joint, in manifest order, under its canonical name.

        A native scene reports it in manifest units (grippers per their read mode). Another
        MuJoCo scene gives raw positions, velocities and actuator efforts; another backend
        gives positions from ``obs["joint_positions"]`` (zeros when absent) and zero
        velocities and efforts.
        """
        obs = self._require_obs()
        if self._manifest_env is not None:
            return self._manifest_env.joint_state()
        handles = self.env.mujoco_handles()
        count = len(self.joint_names)
        if handles is None:
            zeros = np.zeros(count)
            return JointStateSample(
                names=self.joint_names,
                positions=self._positions_from_obs(obs),
                velocities=zeros,
                efforts=zeros.copy(),
                stamp_ns=time.monotonic_ns(),
            )
        model, data = handles
        if model is not self._addr_model:  # a backend rebuilt its model on reset
            self._resolve_addresses(model)
        return JointStateSample(
            names=self.joint_names,
            positions=data.qpos[self._qpos].astype(np.float64),
            velocities=data.qvel[self._dof].astype(np.float64),
            efforts=data.qfrc_actuator[self._dof].astype(np.float64),
            stamp_ns=time.monotonic_ns(),
            sim_time_s=float(data.time),
        )

    def read_images(self) -> dict[str, npt.NDArray[np.uint8]]:
        """Last frame of each manifest RGB sensor the scene renders, by sensor name."""
        images = self._require_obs().get("images") or {}
        return {name: images[name] for name in self._rgb if name in images}

    # -- commands --------------------------------------------------------------------------

    @property
    def episode_done(self) -> bool:
        """True when the last step ended the episode; the next step resets first."""
        return self._episode_done

    @property
    def last_env_action(self) -> FloatArray:
        """A copy of the last commanded scene action (zeros before the first)."""
        return self._last_env_action.copy()

    def send_action(self, action: object) -> None:
        """Step the scene with ``action`` (``action_dim`` values).

        Raises:
            ActionRejected: Wrong type, width, or a non-finite value; nothing is changed.
            EStopLatched: The E-stop is latched.
        """
        self._require_obs()
        values = validated_action(action, self._action_names)
        self._refuse_when_estopped()
        self._reset_if_done()
        self._last_env_action = self.merge(values)
        self._step(self._last_env_action.copy())

    def merge(self, action: FloatArray) -> FloatArray:
        """The scene action to step, from a validated ``action`` and ``_last_env_action``.

        Here the action already is the whole scene action; a HAL that commands only some
        slots of a wider action overrides this to keep the others from the last one.
        """
        return np.array(action, dtype=np.float64)

    @property
    def control_period_s(self) -> float:
        """Simulated time one scene step advances [s]."""
        return self.env.control_period_s

    def tick(self, action: object | None) -> bool:
        """One scene step: with ``action`` (see :meth:`send_action`), or with
        :meth:`hold_action` when None (the targets in force on a position-controlled scene,
        the backend's hold on a delta controller); the commanded action is kept.

        Returns:
            True when the scene stepped; False (nothing done) while E-stopped.

        Raises:
            ActionRejected: ``action`` is malformed; nothing is changed.
        """
        self._require_obs()
        if self._estopped:
            return False
        if action is not None:
            self.send_action(action)
            return True
        self._reset_if_done()
        self._step(self.hold_action())
        return True

    # -- mobile base -----------------------------------------------------------------------

    @property
    def base(self) -> BaseDrive | None:
        """The mobile base's drive (None: a robot without one, or not a native scene)."""
        return self.env.base if isinstance(self.env, NativeScene) else None

    def command_base(self, vx_m_s: float, vy_m_s: float, wz_rad_s: float) -> BaseCommand:
        """Drive the mobile base at this base-frame velocity [m/s, m/s, rad/s], clamped to
        the manifest's limits, until the next command or its ``command_timeout_s`` of
        simulated time; the scene's steps apply it (:meth:`BaseDrive.command`).

        Raises:
            NotConnected: Before connect. EStopLatched: The E-stop is latched.
            ConfigurationError: No mobile base. ActionRejected: A non-finite value.
        """
        self._require_obs()
        self._refuse_when_estopped()
        return self._require_base().command(vx_m_s, vy_m_s, wz_rad_s)

    def base_odometry(self) -> BaseOdometry:
        """The base's pose (odometry frame) and twist (base frame) now (errors as above)."""
        self._require_obs()
        return self._require_base().odometry()

    def estop(self) -> None:
        """Latch the E-stop: actions and base commands are refused, the base halts at once."""
        super().estop()
        if self.base is not None:
            self.base.halt()

    # -- internals -------------------------------------------------------------------------

    def _require_base(self) -> BaseDrive:
        base = self.base
        if base is None:
            raise ConfigurationError(f"{self.description.name} has no mobile base in this scene")
        return base

    def _on_release(self) -> None:
        """A native scene holds the pose the E-stop froze; nothing jumps on release."""
        if self._manifest_env is not None and self._obs is not None:
            self._manifest_env.hold_current_pose()

    def _require_obs(self) -> Observation:
        if self._obs is None:
            raise NotConnected("the HAL is not connected; call connect() first")
        return self._obs

    def _reset_if_done(self) -> None:
        if self._episode_done:
            self._obs = self.env.reset(seed=self.env_reset_seed)
            self._episode_done = False

    def _step(self, action: npt.NDArray[Any]) -> StepResult:
        result = self.env.step(action)
        self._obs = result.obs
        self._episode_done = bool(result.terminated or result.truncated)
        return result

    def _resolve_addresses(self, model: mujoco.MjModel) -> None:
        joint = mujoco.mjtObj.mjOBJ_JOINT
        available = [mujoco.mj_id2name(model, joint, i) for i in range(model.njnt)]
        try:
            resolved = resolve_joint_names(self._mjcf_names, [n for n in available if n])
        except HalError as error:  # the manifest's joints: say so at its joints list
            raise error_at(self.description, ("joints",), str(error)) from None
        ids = [mujoco.mj_name2id(model, joint, resolved[n]) for n in self._mjcf_names]
        bad = [
            resolved[n]
            for n, i in zip(self._mjcf_names, ids, strict=True)
            if not is_scalar_joint(model, i)
        ]
        if bad:
            message = (
                f"scene joints {', '.join(bad)} are not hinge or slide joints; a manifest "
                "joint must map to a one-value joint"
            )
            raise error_at(self.description, ("joints",), message)
        self._qpos = np.array([model.jnt_qposadr[i] for i in ids], dtype=np.intp)
        self._dof = np.array([model.jnt_dofadr[i] for i in ids], dtype=np.intp)
        self._addr_model = model

    def _slot_names(self, width: int) -> tuple[str, ...]:
        if isinstance(self.env, HoldingRollout) and len(self.env.action_names) == width:
            return tuple(self.env.action_names)
        if width == len(self.joint_names):
            return self.joint_names
        return tuple(f"env_action[{i}]" for i in range(width))

    def _positions_from_obs(self, obs: Observation) -> FloatArray:
        count = len(self.joint_names)
        raw = obs.get("joint_positions")
        if raw is None:
            return np.zeros(count)
        values = np.asarray(raw, dtype=np.float64).ravel()
        if values.size != count:
            if not self._warned_width:
                _log.warning(
                    "%s reports %d joint positions but the manifest of %s has %d joints; "
                    "padding with zeros or truncating",
                    type(self.env).__name__,
                    values.size,
                    self.description.name,
                    count,
                )
                self._warned_width = True
            values = np.concatenate([values, np.zeros(max(0, count - values.size))])[:count]
        return values


def native_scene(hal: object) -> NativeScene | None:
    """The native scene behind ``hal`` (it renders cameras and depth on demand), else None."""
    if isinstance(hal, SimAttachedHAL) and isinstance(hal.env, NativeScene):
        return hal.env
    return None
