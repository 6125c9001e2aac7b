"""A gymnasium env for every scene file: the HAL contract, in the API trainers already use.

``make_env("robots/franka_panda/scenes/tabletop.yaml", seed=0)`` (or
``gymnasium.make("openral/Scene-v0", config={"scene": ...})``) builds the scene's HAL with
:func:`~openral_hal.factory.build_hal`, exactly as ``deploy sim`` and ``sim sweep`` do, and
wraps it:

- the observation space is :class:`~openral_eval.env_observation.ObservationLayout`'s
  flat ``Dict`` by the keys every path shares (:mod:`openral_eval.observation_keys`:
  ``observation.state``, ``observation.images.<slot>`` …; joints in manifest units, every
  sensor at its own rate), or the keys named in ``keys``, or those as one vector (``flat``);
- the action space is the scene's action contract in the chosen mode: in
  ``joint_position``, one value per action slot (a native scene: per manifest joint, a
  target in manifest units within the manifest's limits, grippers in their write mode;
  robosuite: its controller's own action within its ``action_spec``), then, on a mobile
  base, the base twist ``vx, vy, wz`` within the manifest's velocity limits;
- ``reset(seed=s)`` draws the scene's randomisation from ``s`` (no seed: one drawn from the
  env's generator, so a seeded env's episodes are reproducible);
- ``step`` returns the scene's reward in ``reward_mode`` (:mod:`openral_sim.task_reward`:
  ``sparse``, 1 at a success step, or ``dense``, the scene's staged terms; robosuite's dense
  is its own reward); ``terminated`` when the scene's own success check holds or the task
  ends it, ``truncated`` at the scene's horizon or ``max_steps``; ``info`` carries
  ``success`` and ``is_success`` (and, from ``reset``, the scene's ``seed``).

Every shipped scene is registered too, as ``openral/<robot>-<scene>-v0`` with its horizon
as ``max_episode_steps`` (:mod:`openral_core.scene_index`); keyword arguments of
:func:`gymnasium.make` are :class:`EnvConfig` fields:
``gymnasium.make("openral/franka_panda-tabletop-v0", reward_mode="dense")``.

An action outside the space (wrong shape, NaN, a value past its slot's bounds) raises
:class:`~openral_mujoco.errors.ActionRejected` naming the slot, before anything moves.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from pathlib import Path
from typing import Any, SupportsFloat, cast

import gymnasium
import numpy as np
import numpy.typing as npt
from gymnasium import spaces
from openral_core.loaded import LoadedRobot
from openral_core.loader import load_scene
from openral_core.paths import repo_root
from openral_core.scene_index import read_scene_index
from openral_hal.factory import HalMode, build_hal
from openral_hal.sim_attached import SimAttachedHAL
from openral_hal.tool_centre import ee_command
from openral_mujoco.action import validated_action
from openral_mujoco.errors import ActionRejected
from openral_sim.rollout import SceneRollout
from openral_sim.scene import scene_robot
from openral_sim.state_sensors import state_sensors_of
from openral_sim.task_reward import sparse_reward

from openral_eval.env_actions import BASE_SLOTS, ActionContract
from openral_eval.env_config import EnvConfig, RewardMode, merged_config
from openral_eval.env_observation import (
    EnvObservation,
    FlatLayout,
    ObservationLayout,
    blank_frames,
    kept_keys,
)

__all__ = [
    "ENV_ID",
    "EnvConfig",
    "RewardMode",
    "SceneEnv",
    "attached_hal",
    "has_dense_reward",
    "make_env",
    "scene_horizon",
]

EnvInfo = dict[str, bool | int]
"""gymnasium's ``info``: ``success`` and ``is_success`` every step, and the scene's ``seed``
at reset."""


ENV_ID = "openral/Scene-v0"
"""The id :func:`gymnasium.make` knows the scene env by once this module is imported."""


class SceneEnv(gymnasium.Env[EnvObservation, npt.NDArray[np.float64]]):
    """One scene as a gymnasium env (see the module doc)."""

    metadata = {"render_modes": ["rgb_array"]}  # noqa: RUF012 (gymnasium's own convention)

    def __init__(
        self,
        config: EnvConfig | Mapping[str, object] | None = None,
        *,
        render_mode: str | None = None,
        hal: tuple[SimAttachedHAL, LoadedRobot] | None = None,
        **settings: object,
    ) -> None:
        """Build the scene's HAL (or use ``hal``, which the env then does not close) and
        lay out the spaces from its first observation. ``settings``: :class:`EnvConfig`
        fields, over ``config``'s (``gymnasium.make``'s keyword arguments).

        Raises:
            ValueError: A bad config, render mode or reward mode. ManifestError: A bad scene
                file.
        """
        self.config = EnvConfig.parse(merged_config(config, settings))
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"unknown render mode {render_mode!r}; valid: rgb_array")
        self.render_mode = render_mode
        self._owns_hal = hal is None
        self.hal, self.robot = hal if hal is not None else attached_hal(self.config.scene)
        self._closer = weakref.finalize(self, self.hal.disconnect) if self._owns_hal else None
        """Closes the scene when the env is closed, collected, or left open at exit (its GL
        contexts freed while the display still exists)."""
        try:
            self._build()
        except BaseException:
            self.close()  # a refused config leaves nothing open
            raise

    def _build(self) -> None:
        """Connect the HAL and lay out the spaces (see :meth:`__init__`)."""
        self._observed = self._chosen_sensors()
        self._choose_sensors(render=False)  # laid out unrendered: see blank_frames
        self.hal.env_reset_seed = 0
        self.hal.release_estop()
        if self.hal.connected:
            self.hal.reset()
        else:
            self.hal.connect()
        self._ee = ee_command(self.hal, self.robot)
        scene = self.hal.env if isinstance(self.hal.env, SceneRollout) else None
        first = self.hal.last_observation()
        self.layout = ObservationLayout(
            self.robot,
            first if scene is None else blank_frames(scene.sensors, self._observed, first),
            self.hal.read_state(),
            privileged=self.config.privileged,
            tcp_pose=self.tcp_pose(),
            only=None if isinstance(self.hal.env, SceneRollout) else self._observed,
        )
        self.kept = kept_keys(self.layout.space, self.config.keys)
        """The observation keys this env returns (``EnvConfig.keys``, else all)."""
        self.flat = FlatLayout(self.layout.space, self.kept) if self.config.flat else None
        """Where each key is in the flat observation (``EnvConfig.flat``; None: a Dict)."""
        kept_space = spaces.Dict({key: self.layout.space[key] for key in self.kept})
        self.observation_space = cast(
            spaces.Space[EnvObservation], kept_space if self.flat is None else self.flat.space
        )
        self.actions = ActionContract(
            self.hal, self.robot, self.config.action_mode, self._ee, self.config.ee_preset
        )
        self.action_names = self.actions.names
        """One name per action value."""
        low, high = self.actions.bounds()
        self.box = spaces.Box(low, high, dtype=np.float64)
        """The action space, typed as what it is."""
        self.action_space = self.box
        self._bounded = bool(np.isfinite(low).all() and np.isfinite(high).all())
        self.steps = 0
        self._limit = self.config.max_steps or scene_horizon(self.hal)
        self._dense = self.config.reward_mode is RewardMode.DENSE
        if self._dense and not has_dense_reward(self.hal):
            raise ValueError(
                f"{self.config.scene} declares no dense reward (reward.dense); valid reward "
                "mode: sparse"
            )
        if self.config.seed is not None:
            self.action_space.seed(self.config.seed)
            super().reset(seed=self.config.seed)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[EnvObservation, EnvInfo]:
        """A new episode: the scene's randomisation drawn from ``seed`` (see the module
        doc); returns the first observation and ``info``."""
        super().reset(seed=seed)
        scene_seed = seed if seed is not None else int(self.np_random.integers(2**31 - 1))
        self.hal.env_reset_seed = scene_seed
        self.hal.release_estop()
        self._choose_sensors()
        self.hal.reset()
        self.actions.reset()
        self.layout.reset()
        self.steps = 0
        obs = self._observe()
        return obs, {"seed": scene_seed, **self._info(success=False)}

    def step(
        self, action: npt.NDArray[np.float64]
    ) -> tuple[EnvObservation, SupportsFloat, bool, bool, EnvInfo]:
        """One control period with ``action`` (see the module doc).

        Raises:
            ActionRejected: ``action`` is outside the action space; nothing moved.
        """
        self.actions.apply(self.checked(action))
        self.steps += 1
        outcome = self.hal.last_outcome
        terminated = outcome.success or outcome.terminated
        truncated = not terminated and (
            outcome.truncated or (self._limit is not None and self.steps >= self._limit)
        )
        obs = self._observe()
        info = self._info(success=outcome.success)
        reward = outcome.dense_reward if self._dense else sparse_reward(outcome.success)
        return obs, reward, terminated, truncated, info

    def checked(self, action: object) -> npt.NDArray[np.float64]:
        """``action`` as float64 values inside the action space, or :class:`ActionRejected`
        naming the first bad slot (a NaN is inside no bounds; an infinite value is outside
        finite ones, so with finite bounds this one comparison is the finite check too)."""
        values = validated_action(action, self.action_names, finite_checked_by_caller=self._bounded)
        space = self.box
        inside = (values >= space.low) & (values <= space.high)
        if not inside.all():
            i = int(np.argmin(inside))
            raise ActionRejected(
                f"action[{i}] ({self.action_names[i]}) is {values[i]:g}; expected within "
                f"[{space.low[i]:g}, {space.high[i]:g}] ({self.actions.mode.value} mode)"
            )
        return values

    def clipped(self, action: object) -> npt.NDArray[np.float64]:
        """``action`` clamped onto the action space, as ``deploy sim`` clamps a command
        onto the manifest's limits (an evaluation episode drives a policy by that contract;
        :meth:`step` itself refuses what is outside). A policy's action has no base slots
        (its contract has none): on a mobile base they are zero, the base stays still.

        Raises:
            ActionRejected: Wrong type or width, or a non-finite value.
        """
        names = self.action_names
        if self.actions.base:
            names = names[: -len(BASE_SLOTS)]
        values = validated_action(action, names)
        if self.actions.base:
            values = np.concatenate([values, np.zeros(len(BASE_SLOTS))])
        return np.clip(values, self.box.low, self.box.high)

    def render(self) -> npt.NDArray[np.uint8] | None:
        """A frame of the scene's first camera as the scene is now, rendered on demand
        whatever ``sensors`` chose (robosuite: its latest frame); None without a render
        mode or a camera."""
        if self.render_mode is None or not self.hal.env.camera_names:
            return None
        camera = self.hal.env.camera_names[0]
        scene = self.hal.env
        handles = scene.mujoco_handles()
        if isinstance(scene, SceneRollout) and handles is not None:
            return scene.render_cameras(handles[1], [camera])[camera]
        return self.hal.read_images().get(camera)

    def close(self) -> None:
        """Close the scene (an env given a HAL leaves it open for its owner)."""
        if self._closer is not None:
            self._closer()

    def _observe(self) -> EnvObservation:
        obs = self.hal.last_observation()  # a native scene's carries the HAL's joint sample
        full = self.layout.observe(obs, obs.joints or self.hal.read_state(), self.tcp_pose())
        kept = full if len(self.kept) == len(full) else {key: full[key] for key in self.kept}
        return kept if self.flat is None else self.flat.flat(kept)  # type: ignore[return-value]

    def tcp_pose(self) -> npt.NDArray[np.float64] | None:
        """The measured TCP pose in the base frame (None: no TCP here)."""
        if self._ee is None:
            return None
        handles = self.hal.mujoco_handles()
        return None if handles is None else self._ee.tcp_vector(handles[1])

    @staticmethod
    def _info(*, success: bool) -> EnvInfo:
        """Only what a trainer needs each step (a vector env merges every key of every env
        on every step: each costs its share of the step)."""
        return {"success": success, "is_success": success}

    def _chosen_sensors(self) -> frozenset[str] | None:
        """The sensors the config asks for (None: all); unknown names are refused.

        Raises:
            ValueError: A name that is no sensor of the manifest.
        """
        chosen = self.config.sensors
        if chosen is True:
            return None
        names = () if chosen is False else tuple(chosen)
        known = {sensor.name for sensor in self.robot.description.sensors}
        unknown = sorted(set(names) - known)
        if unknown:
            raise ValueError(
                f"env config sensors {unknown} are not sensors of {self.robot.name}; "
                f"valid: {sorted(known)}"
            )
        states = {sensor.name for _, sensor in state_sensors_of(self.robot.description)}
        return frozenset(names) | states

    def _choose_sensors(self, *, render: bool = True) -> None:
        """Let a native scene render the chosen sensors into its observations, or nothing
        (a HAL shared with another env may have been told otherwise)."""
        scene = self.hal.env if isinstance(self.hal.env, SceneRollout) else None
        if scene is not None:
            scene.observed = self._observed
            scene.render_observations = render


def attached_hal(scene_file: str) -> tuple[SimAttachedHAL, LoadedRobot]:
    """The HAL :func:`~openral_hal.factory.build_hal` attaches to ``scene_file`` (not yet
    connected), and its robot."""
    scene = load_scene(Path(scene_file))
    robot = scene_robot(scene)
    hal = build_hal(robot, mode=HalMode.SIM, scene=scene)
    if not isinstance(hal, SimAttachedHAL):  # build_hal attaches every scene
        raise TypeError(f"build_hal gave a {type(hal).__name__} for scene {scene_file}")
    return hal, robot


def has_dense_reward(hal: SimAttachedHAL) -> bool:
    """True when the scene ``hal`` is attached to has a dense reward (robosuite: its own)."""
    return not isinstance(hal.env, SceneRollout) or hal.env.task.dense is not None


def scene_horizon(hal: SimAttachedHAL) -> int | None:
    """Steps per episode of the scene ``hal`` is attached to (None: it sets none)."""
    return hal.env.horizon if isinstance(hal.env, SceneRollout) else None


def make_env(scene: str | Path, **config: object) -> SceneEnv:
    """The env of ``scene``; ``config``: the other :class:`EnvConfig` fields."""
    return SceneEnv({"scene": str(scene), **config})


gymnasium.register(id=ENV_ID, entry_point=f"{__name__}:SceneEnv")
for _entry in read_scene_index():
    gymnasium.register(
        id=_entry.env_id,
        entry_point=f"{__name__}:SceneEnv",
        max_episode_steps=_entry.horizon,
        kwargs={"config": {"scene": str(repo_root() / _entry.file)}},
    )
