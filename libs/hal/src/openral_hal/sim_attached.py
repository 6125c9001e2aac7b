"""SimAttachedHAL: a HAL that drives a scene it does not own the physics of.

Under ``deploy sim`` with a scene file, the scene backend (a :class:`SimRollout`) owns
physics and pixels; this HAL is the robot-side view of it: an action is one ``env.step``,
camera frames come from the last observation. A native scene drives its robot by the
manifest's contract (:class:`~openral_sim.rollout.ManifestRollout`: one value per manifest
joint, its own joint state in manifest units); robosuite keeps its controller's action and
its joint state is read from the MuJoCo data by joint name. The deploy control loop
advances the scene with :meth:`SimAttachedHAL.tick` (one state period: a part of a step on a
native scene). A mobile base in a native scene also takes velocity commands
(:meth:`SimAttachedHAL.command_base`, refused while E-stopped) and reports odometry.
"""

from __future__ import annotations

import logging
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import RgbSensor, RobotDescription
from openral_mujoco.action import split_action, validated_action
from openral_mujoco.state import FloatArray, JointStateSample
from openral_sim.base_drive import BaseCommand, BaseDrive, BaseOdometry
from openral_sim.frame_tree import FrameTree
from openral_sim.hold import hold_action
from openral_sim.observation import ImageArray, Observation, Outcome, StepResult
from openral_sim.rollout import HoldingRollout, ManifestRollout, SceneRollout, SimRollout

from openral_hal.attached_sensors import AttachedSensors
from openral_hal.errors import ConfigurationError, HalError, NotConnected
from openral_hal.estop import EStopLatch
from openral_hal.scene_joints import SceneJointReader

_log = logging.getLogger(__name__)


class SimAttachedHAL(AttachedSensors, EStopLatch):
    """A robot inside a simulated scene; one action is one step of the scene.

    The action is the scene's own action (``action_dim`` values): one per manifest joint on
    a native scene, whatever its controller takes on robosuite. The sensors a native scene
    serves off its step are the HAL's sensor sources (:class:`AttachedSensors`).
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
        self._scene = env if isinstance(env, SceneRollout) else None
        self._suite = self._scene.sensors if self._scene is not None else None
        self.robot = robot
        description = robot.description
        self.env_reset_seed = env_reset_seed
        self.env_action_dim = env_action_dim
        self.joint_names = tuple(j.name for j in description.joints)
        self._rgb = tuple(s.name for s in description.sensors if isinstance(s, RgbSensor))
        self._action_dim: int | None = None
        self._action_names: tuple[str, ...] = ()
        self._obs: Observation | None = None
        self._last_env_action: FloatArray = np.zeros(0)
        self._outcome = Outcome()
        self._frames: dict[str, ImageArray] = {}
        self._closed = False
        mjcf_names = tuple(robot.tables.joint_name_map[n] for n in self.joint_names)
        self._joints = SceneJointReader(description, mjcf_names, type(env).__name__)
        wiring = robot.tables.hal_wiring
        self._gripper = wiring.first_gripper if wiring is not None else None
        """The first gripper's joint (the slot an :class:`Action`'s ``gripper`` sets)."""

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
            self._joints.locate(handles[0])
        self._action_dim = width
        self._action_names = self._slot_names(width)
        self._last_env_action = np.zeros(width)
        self._outcome = Outcome()
        self._observed(obs)

    @property
    def action_names(self) -> tuple[str, ...]:
        """One name per action slot: the backend's, else the manifest joints when the widths
        agree, else ``env_action[i]`` (empty until :meth:`connect` learns the width)."""
        return self._action_names

    def hold_action(self) -> FloatArray:
        """The action that keeps the robot still (:func:`openral_sim.hold.hold_action`: the
        backend's hold, else zeros)."""
        return hold_action(self.env, self.action_dim)

    def disconnect(self) -> None:
        """Close the scene (renderers and all); the HAL cannot be connected again."""
        if not self._closed:
            self.env.close()
            self._closed = True
        self._obs = None
        self._frames.clear()
        self._action_dim = None
        self._action_names = ()

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        """The scene's live MuJoCo (model, data), or None for a non-MuJoCo backend."""
        return self.env.mujoco_handles()

    def frame_tree(self) -> FrameTree | None:
        """The TF frames of the robot and its sensors in a native scene (None for another
        backend; see :mod:`openral_sim.frame_tree`).

        Raises:
            HalError: The model's layout cannot be stated as a tree (see the message).
        """
        return self._scene.frames() if self._scene is not None else None

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
        gives positions from ``obs.joints`` (zeros when absent) and zero
        velocities and efforts.
        """
        obs = self._require_obs()
        if self._manifest_env is not None:
            return self._manifest_env.joint_state()
        return self._joints.read(self.env.mujoco_handles(), obs)

    def read_images(self) -> dict[str, npt.NDArray[np.uint8]]:
        """Latest frame of each manifest RGB sensor the scene's observations carried (each
        camera's frames come at its own rate), by sensor name."""
        self._require_obs()
        return {name: self._frames[name] for name in self._rgb if name in self._frames}

    def render_in_observations(self, enabled: bool) -> bool:
        """Let the scene's steps render sensor frames into observations or not (a bridge
        that renders them itself turns this off, and the frames kept so far are dropped:
        they would only grow stale); returns the previous setting."""
        if self._scene is None:
            return False
        before = self._scene.render_observations
        self._scene.render_observations = enabled
        if not enabled:
            self._frames.clear()
        return before

    def last_observation(self) -> Observation:
        """The scene's latest observation (its frames: those due at that step); raises
        NotConnected before connect."""
        return self._require_obs()

    # -- commands --------------------------------------------------------------------------

    @property
    def last_outcome(self) -> Outcome:
        """How the scene's last step ended (reward, success, terminated, truncated)."""
        return self._outcome

    @property
    def episode_done(self) -> bool:
        """True when the last step ended the episode; the next step resets first."""
        return self._outcome.done

    @property
    def last_env_action(self) -> FloatArray:
        """A copy of the last commanded scene action (zeros before the first)."""
        return self._last_env_action.copy()

    def send_action(self, action: object) -> None:
        """Step the scene with ``action``: ``action_dim`` values, or a typed
        :class:`~openral_mujoco.action.Action` (named slots, the gripper, a base twist).

        Raises:
            ActionRejected: Wrong type, width, or a non-finite value; nothing is changed.
            EStopLatched: The E-stop is latched.
        """
        self._command(action, glide=False)

    def merge(self, action: FloatArray) -> FloatArray:
        """The scene action to step from a validated ``action`` (here the whole of it; a HAL
        commanding some slots of a wider action keeps the others from the last one)."""
        return np.array(action, dtype=np.float64)

    @property
    def control_period_s(self) -> float:
        """Simulated time one scene step advances [s]."""
        return self.env.control_period_s

    @property
    def state_parts(self) -> int:
        """Parts of a control period :meth:`tick_part` steps (a native scene's state rate;
        1 for another backend)."""
        return self._scene.parts if self._scene is not None else 1

    def tick(self, action: object | None, *, glide: bool = False) -> bool:
        """One scene step: with ``action`` (see :meth:`send_action`; ``glide`` as
        :meth:`Tickable.tick <openral_hal.protocol.Tickable.tick>` says, on a native scene),
        or with :meth:`hold_action` when None (the targets in force on a position-controlled
        scene, the backend's hold on a delta controller); the commanded action is kept.
        Returns True when the scene stepped, False (nothing done) while E-stopped.

        Raises:
            ActionRejected: ``action`` is malformed; nothing is changed.
        """
        return self._tick(action, glide, part=False)

    def tick_part(self, action: object | None, *, glide: bool = False) -> bool:
        """One of :attr:`state_parts` parts of a scene step, as :meth:`tick` but: ``action``
        starts a new step with it; None steps the next part (or starts a step holding)."""
        return self._tick(action, glide, part=True)

    def _tick(self, action: object | None, glide: bool, part: bool) -> bool:
        self._require_obs()
        if self._estopped:
            return False
        if action is not None:
            self._command(action, glide=glide, part=part)
            return True
        self._reset_if_done()
        if part and self._scene is not None:
            self._stepped(self._scene.step_part(None))
        else:
            self._step(self.hold_action())
        return True

    def reset(self) -> str:
        """A new episode of the scene with the HAL's seed: start pose, objects, a mobile
        base at its start; the E-stop latch is kept (an E-stopped scene stays frozen)."""
        self._require_obs()
        obs = self.env.reset(seed=self.env_reset_seed)
        self._observed(obs)
        self._outcome = Outcome()
        self._last_env_action = np.zeros(self.action_dim)
        clock = f"; simulated time {obs.time_s:.3f} s"
        latch = "; the E-stop is still latched" if self._estopped else ""
        return (
            f"{self.description.name}: scene reset with seed {self.env_reset_seed} "
            f"(start pose, objects{', mobile base' if self.base is not None else ''}){clock}"
            f"{latch}"
        )

    # -- mobile base -----------------------------------------------------------------------

    @property
    def base(self) -> BaseDrive | None:
        """The mobile base's drive (None: a robot without one, or not a native scene)."""
        return self._scene.base if self._scene is not None else None

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

    def _on_latch(self) -> None:
        """The E-stop halts the mobile base at once (:mod:`openral_hal.estop`)."""
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

    def _observed(self, obs: Observation) -> None:
        """Keep ``obs`` and the latest frame of each camera."""
        self._obs = obs
        self._frames.update(obs.images)

    def _reset_if_done(self) -> None:
        if self._outcome.done:
            self._observed(self.env.reset(seed=self.env_reset_seed))
            self._outcome = Outcome()

    def _command(self, action: object, *, glide: bool, part: bool = False) -> None:
        """Validate everything first (a refused action changes nothing), then step."""
        self._require_obs()
        joints, twist = split_action(action, self._action_names, self.hold_action, self._gripper)
        values = validated_action(joints, self._action_names)
        self._refuse_when_estopped()
        base = self._require_base() if twist is not None else None
        self._reset_if_done()
        if base is not None and twist is not None:
            base.command(twist.vx_m_s, twist.vy_m_s, twist.wz_rad_s)
        self._last_env_action = self.merge(values)
        self._step(self._last_env_action.copy(), glide=glide, part=part)

    def _step(self, action: npt.NDArray[Any], *, glide: bool = False, part: bool = False) -> None:
        """One scene step with ``action`` (``part``: its first part only, on a native scene)."""
        if part and self._scene is not None:
            result = self._scene.step_part(action, glide=glide)
        elif glide and self._manifest_env is not None:
            result = self._manifest_env.step(action, glide=True)
        else:
            result = self.env.step(action)
        self._stepped(result)

    def _stepped(self, result: StepResult) -> None:
        self._observed(result.obs)
        self._outcome = result.outcome

    def _slot_names(self, width: int) -> tuple[str, ...]:
        if isinstance(self.env, HoldingRollout) and len(self.env.action_names) == width:
            return tuple(self.env.action_names)
        if width == len(self.joint_names):
            return self.joint_names
        return tuple(f"env_action[{i}]" for i in range(width))
