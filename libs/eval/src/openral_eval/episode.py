"""One evaluation episode: a policy drives a scene through the HAL until success or a limit.

An episode is a pure function of its :class:`EpisodeSpec` (scene file, seed, policy and its
parameters, step limit): :func:`run_episode` resets the scene with the seed (its declared
randomisation), then, once per control step, builds the policy's observation, takes its
action and hands it to the HAL :func:`~openral_hal.factory.build_hal` attached to the
scene, exactly the contract ``deploy sim`` drives (manifest units, limits, the E-stop),
through the scene's gymnasium env (:class:`~openral_eval.scene_env.SceneEnv`, the one
``make_env`` gives trainers): the same reset, action check and end of episode.
It ends when the scene reports success (the step's :class:`~openral_sim.observation.Outcome`:
a native scene's ``success`` predicates, robosuite's own check), when the scene ends the
episode (its horizon), or after ``steps`` steps.

Cameras are rendered at their own rates (:mod:`openral_sim.sensor_schedule`), and only
those the policy's slots and the video need: a policy sees each camera's latest frame, and
the video has one frame per frame of its camera.

Nothing in it depends on the process or on earlier episodes: the same spec gives the same
joint trajectory serially, in a process pool and on Ray (``trajectory_sha256`` hashes
every joint position the policy saw). A scene and its HAL are built once per process and
reused (:func:`scene_for`); an episode that raises (a diverged simulation, a policy error) is a
result with its ``error``, never an exception.
"""

from __future__ import annotations

import atexit
import hashlib
import time
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import mujoco
import numpy as np
from openral_core.loaded import LoadedRobot
from openral_hal.sim_attached import SimAttachedHAL
from openral_sim.observation import Observation as SceneObservation
from openral_sim.rollout import SceneRollout
from openral_sim.sensor_schedule import sensor_rates

from openral_eval import observation_keys as keys
from openral_eval.env_actions import ActionMode
from openral_eval.env_policy import policy_observation
from openral_eval.episode_frames import EpisodeFrames, as_stored, dataset_cameras
from openral_eval.policies import make_policy
from openral_eval.policy import Observation, PolicyAdapter, action_mode
from openral_eval.privileged import Pose, Privileged, PrivilegedGripper
from openral_eval.remote_policy import RemotePolicy
from openral_eval.scene_env import EnvConfig, SceneEnv, attached_hal, scene_horizon
from openral_eval.video import VideoWriter

DEFAULT_STEPS = 300
"""Step limit of an episode when neither the sweep nor the scene's horizon sets one."""


@dataclass(frozen=True)
class EpisodeSpec:
    """Everything an episode depends on."""

    scene: str
    """The scene file, as the user named it (results carry it verbatim)."""
    seed: int
    policy: str
    params: tuple[tuple[str, str], ...] = ()
    """The policy's ``key=value`` parameters, sorted."""
    steps: int | None = None
    """Step limit (None: the scene's horizon, else :data:`DEFAULT_STEPS`)."""
    video: str | None = None
    """Write an MP4 of the scene's first camera here (None: no video)."""
    dataset: str | None = None
    """Keep every step (state, action, success, each VLA camera's frame) for a dataset in
    this ``.npz`` (None: keep nothing; :mod:`openral_eval.episode_frames`)."""

    @property
    def key(self) -> tuple[str, int, str, tuple[tuple[str, str], ...]]:
        """What identifies an episode in a results file."""
        return (self.scene, self.seed, self.policy, self.params)


@dataclass(frozen=True)
class EpisodeResult:
    """What one episode did (one line of ``episodes.jsonl``)."""

    scene: str
    seed: int
    policy: str
    params: dict[str, str]
    success: bool
    steps: int
    sim_time_s: float
    wall_time_s: float
    error: str | None
    trajectory_sha256: str
    video: str | None = None
    frames: int = 0
    """Camera frames the scene rendered for the episode (each camera at its own rate, only
    those the policy and the video read)."""
    clamped_steps: int = 0
    """Steps whose action the policy gave outside the action space (clamped onto it)."""

    @classmethod
    def unfinished(
        cls, spec: EpisodeSpec, why: str, steps: int = 0, wall_time_s: float = 0.0
    ) -> EpisodeResult:
        """The result of an episode that never finished (its worker died or was stopped
        after ``steps`` steps and ``wall_time_s`` [s])."""
        return cls(
            spec.scene,
            spec.seed,
            spec.policy,
            dict(spec.params),
            False,
            steps,
            0.0,
            round(wall_time_s, 4),
            why,
            "",
        )


_HALS: dict[str, tuple[SimAttachedHAL, LoadedRobot]] = {}
"""This process's scenes (attached HALs) by file, built on first use."""
_ENVS: dict[tuple[str, tuple[str, ...], int, str], SceneEnv] = {}
"""This process's envs on those HALs, by scene, rendered sensors, step limit and mode."""


def scene_for(path: str) -> tuple[SimAttachedHAL, LoadedRobot]:
    """The HAL of the scene of ``path`` and its robot, built once per process by
    :func:`~openral_hal.factory.build_hal`."""
    if path not in _HALS:
        built = attached_hal(path)
        if not _HALS:
            atexit.register(close_scenes)
        _HALS[path] = built
    return _HALS[path]


def close_scenes() -> None:
    """Disconnect this process's scenes (their renderers' GL contexts are freed while the
    display still exists, not at the interpreter's teardown)."""
    _ENVS.clear()
    while _HALS:
        _, (hal, _) = _HALS.popitem()
        hal.disconnect()


class StepCount(Protocol):
    """Where a worker process tells its pool how far its episode got (a shared value)."""

    value: int


step_count: StepCount | None = None
"""Set in a sweep's worker process: each step of its episode is counted here, so an
episode that is stopped (it hung) or kills its process is recorded with its steps."""

StepWatch = Callable[[Mapping[str, float] | None], None]
"""Called after the reset (None) and after each step (its action, by the env's slot
names): a browser view's feed."""


def run_episode(spec: EpisodeSpec, watch: StepWatch | None = None) -> EpisodeResult:
    """Run one episode (see the module doc); errors become the result's ``error``. A
    ``watch`` sees every step, and every camera of the scene is rendered for it."""
    started = time.perf_counter()
    digest = hashlib.sha256()
    run, error = _Run(), None
    try:
        _drive(spec, digest, watch, run)
    except Exception as failure:  # the sweep goes on; the result says what happened
        frame = traceback.extract_tb(failure.__traceback__)[-1]
        error = f"{type(failure).__name__}: {failure} ({Path(frame.filename).name}:{frame.lineno})"
    return EpisodeResult(
        scene=spec.scene,
        seed=spec.seed,
        policy=spec.policy,
        params=dict(spec.params),
        success=run.success,
        steps=run.steps,
        sim_time_s=round(run.sim_time_s, 9),
        wall_time_s=round(time.perf_counter() - started, 4),
        error=error,
        trajectory_sha256=digest.hexdigest(),
        video=spec.video,
        frames=run.frames,
        clamped_steps=run.clamped_steps,
    )


@dataclass
class _Run:
    """What :func:`_drive` measured of one episode."""

    steps: int = 0
    success: bool = False
    sim_time_s: float = 0.0
    frames: int = 0
    clamped_steps: int = 0


def _drive(spec: EpisodeSpec, digest: hashlib._Hash, watch: StepWatch | None, run: _Run) -> None:
    """Count the steps, success, simulated time [s] and frames of one episode into ``run``
    as it goes (an episode that raises keeps what it counted); may raise."""
    hal, robot = scene_for(spec.scene)
    policy = make_policy(spec.policy, dict(spec.params))
    inputs = _Inputs(hal, robot, policy)
    camera = inputs.video_camera(spec.video)
    video = VideoWriter.for_camera(spec.video, camera, camera_rate_hz(hal, robot, camera))
    keep = _kept(spec, robot, hal.env.camera_names)
    wanted = {*inputs.sensors(camera), *(keep.cameras.values() if keep else ())}
    sensors = tuple(sorted(wanted | (set(hal.env.camera_names) if watch else set())))
    env = env_for(spec, sensors, action_mode(policy))
    seen, _ = env.reset(seed=spec.seed)
    if watch is not None:
        watch(None)
    run.frames, started = len(hal.last_observation().images), hal.read_state().sim_time_s
    try:
        done = False
        while not done:
            state = hal.read_state()
            digest.update(state.positions.tobytes())
            video.add(hal.last_observation())
            obs = inputs.observation(env, seen)
            # float32, as a dataset stores it, in every episode: a sweep with --dataset, one
            # without and `sim export`'s rerun of it apply the same values (same digest)
            asked = policy.act(obs)
            clipped = env.clipped(asked)
            run.clamped_steps += _clamped(asked, clipped)
            action = as_stored(clipped, env.box.low, env.box.high)
            frames = hal.read_images() if keep is not None else {}
            seen, _, terminated, truncated, info = env.step(action)
            if watch is not None:
                watch(dict(zip(env.action_names, action.tolist(), strict=True)))
            run.steps += 1
            if step_count is not None:
                step_count.value = run.steps
            run.frames += len(hal.last_observation().images)
            run.success = bool(info["success"])
            if keep is not None:  # a dataset row holds what the policy saw
                _keep_step(keep, obs, (action, run.success), frames, hal.read_state().names)
            done = terminated or truncated
        video.add(hal.last_observation())
        if keep is not None:
            keep.save()
    finally:
        video.close()
        if isinstance(policy, RemotePolicy):  # its connection ends with the episode
            policy.close()
    digest.update(hal.read_state().positions.tobytes())
    run.sim_time_s = float(hal.read_state().sim_time_s or 0.0) - float(started or 0.0)


def _keep_step(
    keep: EpisodeFrames,
    obs: Observation,
    taken: tuple[np.ndarray, bool],
    frames: dict[str, np.ndarray],
    joints: tuple[str, ...],
) -> None:
    """One dataset row: the state and the other vectors the policy saw (``obs``; ``joints``
    names the joints), the action taken and success after it, the cameras' frames."""
    state = keys.vector_of(obs, keys.STATE)
    assert state is not None
    action, success = taken
    keep.add(state, action, success, frames, keys.named_vectors(obs, joints))


def _clamped(wanted: object, clipped: np.ndarray) -> bool:
    """True when ``clipped`` (the env's clamp of ``wanted``, base slots appended) differs."""
    values = np.asarray(wanted, dtype=np.float64).ravel()
    return bool(np.any(values != clipped[: values.size]))


def _kept(spec: EpisodeSpec, robot: LoadedRobot, rendered: tuple[str, ...]) -> EpisodeFrames | None:
    """Where an episode of a ``--dataset`` sweep keeps its steps (None: it keeps none)."""
    if spec.dataset is None:
        return None
    return EpisodeFrames(Path(spec.dataset), dataset_cameras(robot, rendered))


def env_for(spec: EpisodeSpec, sensors: tuple[str, ...], mode: str) -> SceneEnv:
    """The gymnasium env an episode steps (the one :func:`~openral_eval.make_env` gives, on
    this process's HAL of the scene): ``sensors`` rendered, actions in ``mode``, truncated
    at the step limit."""
    hal, robot = scene_for(spec.scene)
    limit = spec.steps or scene_horizon(hal) or DEFAULT_STEPS
    key = (spec.scene, sensors, limit, mode)
    if key not in _ENVS:
        config = EnvConfig(
            spec.scene, sensors=sensors, max_steps=limit, action_mode=ActionMode(mode)
        )
        _ENVS[key] = SceneEnv(config, hal=(hal, robot))
    return _ENVS[key]


def camera_rate_hz(hal: SimAttachedHAL, robot: LoadedRobot, camera: str | None) -> float:
    """The rate ``camera``'s frames come at in the scene's observations [Hz] (1 without a
    camera)."""
    if camera is None:
        return 1.0
    control_hz = 1.0 / hal.control_period_s
    return sensor_rates(robot.description, control_hz, sensors=[camera])[camera]


class _Inputs:
    """Builds a policy's observation each step: the latest frame of each camera by VLA slot
    when it needs cameras, the task state and the simulation when it asks for them."""

    def __init__(self, hal: SimAttachedHAL, robot: LoadedRobot, policy: PolicyAdapter) -> None:
        self.hal, self.policy, self.robot = hal, policy, robot
        self.scene = hal.env if isinstance(hal.env, SceneRollout) else None
        slots = {slot.slot: slot.sensor for slot in robot.tables.vla_slots}
        self.slots = {slot: slots[slot] for slot in policy.required_slots if slot in slots}
        """Slot the policy requires → its camera."""
        missing = [slot for slot in policy.required_slots if slot not in slots]
        if missing:
            raise ValueError(
                f"policy {type(policy).__name__} needs camera slots {missing}; "
                f"{robot.name} has {sorted(slots)}"
            )
        self.scratch: mujoco.MjData | None = None

    def video_camera(self, path: str | None) -> str | None:
        """The camera a video shows: the scene's first (None: no video or no camera)."""
        names = self.hal.env.camera_names
        return names[0] if path is not None and names else None

    def sensors(self, video_camera: str | None) -> tuple[str, ...]:
        """The only cameras to render: those the policy and the video read."""
        wanted = {*self.slots.values(), *([video_camera] if video_camera else [])}
        return tuple(sorted(wanted))

    def observation(self, env: SceneEnv, seen: Mapping[str, object]) -> Observation:
        """The policy's observation at ``env``'s step: the env's observation ``seen`` as
        :func:`~openral_eval.env_policy.policy_observation` gives it to a policy in the
        env's own loop (the same keys, the action spec, the time), and what a privileged
        policy asks for."""
        hal = self.hal
        missing = [cam for slot, cam in self.slots.items() if keys.image_key(slot) not in seen]
        if missing:
            raise ValueError(f"the scene renders no frame of {missing}")
        obs = policy_observation(env, seen)
        if self.policy.needs_privileged:
            scene_obs = hal.last_observation()
            obs[keys.ENVIRONMENT_STATE] = keys.environment_state(scene_obs.task_state)
            obs[keys.TASK_STATE] = dict(scene_obs.task_state)
            if self.scene is not None:
                obs[keys.PRIVILEGED] = self._privileged(self.scene, scene_obs)
        return obs

    def _privileged(self, scene: SceneRollout, scene_obs: SceneObservation) -> Privileged:
        handles = scene.mujoco_handles()
        if handles is None:  # a native scene always has them
            raise ValueError("a policy with privileged state needs a MuJoCo scene")
        model, data = handles
        if self.scratch is None:
            self.scratch = mujoco.MjData(model)
        mujoco.mj_copyData(self.scratch, model, data)
        slots = scene.addresses.arm_slots
        return Privileged(
            model=model,
            data=self.scratch,
            objects=object_poses(scene_obs),
            arm_slots=tuple(int(s) for s in slots),
            arm_dofs=tuple(int(d) for d in scene.addresses.qvel[slots]),
            grippers=self._grippers(),
            base=scene.frames().base_pose(self.scratch),
        )

    def _grippers(self) -> tuple[PrivilegedGripper, ...]:
        """The manifest's grippers: their action slots."""
        wiring = self.robot.tables.hal_wiring
        names = self.hal.action_names
        return tuple(
            PrivilegedGripper(slot=names.index(g.joint))
            for g in (wiring.grippers if wiring is not None else ())
            if g.joint in names
        )


def object_poses(obs: SceneObservation) -> dict[str, Pose]:
    """World pose of every object a native scene reports (``<name>_pos``/``<name>_quat``)."""
    state = obs.task_state
    names = [key[: -len("_pos")] for key in state if key.endswith("_pos")]
    return {name: (state[f"{name}_pos"], state[f"{name}_quat"]) for name in names}
