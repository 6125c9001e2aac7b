"""One evaluation episode: a policy drives a scene through the HAL until success or a limit.

An episode is a pure function of its :class:`EpisodeSpec` (scene file, seed, policy and its
parameters, step limit): :func:`run_episode` resets the scene with the seed (its declared
randomisation), then, once per control step, builds the policy's observation, takes its
action and hands it to :class:`~openral_hal.sim_attached.SimAttachedHAL`, exactly the
contract ``deploy sim`` drives (manifest units, limits, the E-stop). It ends when the
scene reports success (``info["success"]`` of a native scene with ``success`` predicates),
when the scene ends the episode (its horizon), or after ``steps`` steps.

Nothing in it depends on the process or on earlier episodes: the same spec gives the same
joint trajectory serially, in a process pool and on Ray (``trajectory_sha256`` hashes
every joint position the policy saw). A scene is built once per process and reused
(:func:`scene_for`); an episode that raises (a diverged simulation, a policy error) is a
result with its ``error``, never an exception.
"""

from __future__ import annotations

import hashlib
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from openral_core.loaded import LoadedRobot
from openral_core.loader import load_scene
from openral_hal.sim_attached import SimAttachedHAL
from openral_sim.native_scene import NativeScene
from openral_sim.rollout import SimRollout
from openral_sim.scene import build_scene, scene_robot

from openral_eval.policies import Observation, PolicyAdapter, make_policy
from openral_eval.privileged import Pose, Privileged
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

    @classmethod
    def unfinished(cls, spec: EpisodeSpec, why: str) -> EpisodeResult:
        """The result of an episode that never finished (its worker died)."""
        return cls(
            spec.scene, spec.seed, spec.policy, dict(spec.params), False, 0, 0.0, 0.0, why, ""
        )


_SCENES: dict[str, tuple[SimRollout, LoadedRobot]] = {}
"""This process's scenes by file, built on first use."""


def scene_for(path: str) -> tuple[SimRollout, LoadedRobot]:
    """The scene of ``path`` and its robot, built once per process (cameras render on
    demand, not into every observation)."""
    if path not in _SCENES:
        scene = load_scene(Path(path))
        robot = scene_robot(scene)
        _SCENES[path] = (build_scene(scene, robot, render_observations=False), robot)
    return _SCENES[path]


def run_episode(spec: EpisodeSpec) -> EpisodeResult:
    """Run one episode (see the module doc); errors become the result's ``error``."""
    started = time.perf_counter()
    digest = hashlib.sha256()
    steps, success, sim_time, error = 0, False, 0.0, None
    try:
        steps, success, sim_time = _drive(spec, digest)
    except Exception as failure:  # the sweep goes on; the result says what happened
        frame = traceback.extract_tb(failure.__traceback__)[-1]
        error = f"{type(failure).__name__}: {failure} ({Path(frame.filename).name}:{frame.lineno})"
    return EpisodeResult(
        scene=spec.scene,
        seed=spec.seed,
        policy=spec.policy,
        params=dict(spec.params),
        success=success,
        steps=steps,
        sim_time_s=round(sim_time, 9),
        wall_time_s=round(time.perf_counter() - started, 4),
        error=error,
        trajectory_sha256=digest.hexdigest(),
        video=spec.video,
    )


def _drive(spec: EpisodeSpec, digest: hashlib._Hash) -> tuple[int, bool, float]:
    """(steps, success, simulated time [s]) of one episode; may raise."""
    env, robot = scene_for(spec.scene)
    policy = make_policy(spec.policy, dict(spec.params))
    hal = SimAttachedHAL(env, robot, env_reset_seed=spec.seed)
    hal.connect()
    limit = spec.steps or _horizon(env) or DEFAULT_STEPS
    video = VideoWriter.for_scene(spec.video, env)
    inputs = _Inputs(env, robot, policy)
    steps, success, started = 0, False, hal.read_state().sim_time_s or 0.0
    try:
        while steps < limit and not success:
            state = hal.read_state()
            digest.update(state.positions.tobytes())
            video.add(env)
            hal.send_action(policy.act(inputs.observation(hal, state.positions, steps)))
            steps += 1
            success = bool(hal.last_step_info.get("success", False))
            if hal.episode_done and not success:
                break
        video.add(env)
    finally:
        video.close()
    digest.update(hal.read_state().positions.tobytes())
    return steps, success, float(hal.read_state().sim_time_s or 0.0) - started


def _horizon(env: SimRollout) -> int | None:
    return env.horizon if isinstance(env, NativeScene) else None


class _Inputs:
    """Builds a policy's observation each step: frames by VLA slot when it needs cameras,
    privileged state when it asks for it."""

    def __init__(self, env: SimRollout, robot: LoadedRobot, policy: PolicyAdapter) -> None:
        self.env, self.policy = env, policy
        slots = {slot.slot: slot.sensor for slot in robot.tables.vla_slots}
        self.slots = {slot: slots[slot] for slot in policy.required_slots if slot in slots}
        missing = [slot for slot in policy.required_slots if slot not in slots]
        if missing:
            raise ValueError(
                f"policy {type(policy).__name__} needs camera slots {missing}; "
                f"{robot.name} has {sorted(slots)}"
            )
        self.scratch: mujoco.MjData | None = None

    def observation(self, hal: SimAttachedHAL, positions: np.ndarray, step: int) -> Observation:
        images = {}
        if self.slots:
            if not isinstance(self.env, NativeScene):
                frames = hal.read_images()
                images = {slot: frames[sensor] for slot, sensor in self.slots.items()}
            else:
                rendered = self.env.render_cameras(self.env.data, list(self.slots.values()))
                images = {slot: rendered[sensor] for slot, sensor in self.slots.items()}
        obs: Observation = {
            "images": images,
            "joint_positions": positions,
            "action_spec": (hal.action_names, hal.hold_action()),
            "time_s": step * hal.control_period_s,
        }
        if getattr(self.policy, "needs_privileged", False):
            obs["privileged"] = self._privileged()
        return obs

    def _privileged(self) -> Privileged:
        env = self.env
        if not isinstance(env, NativeScene):
            raise ValueError("a policy with privileged state needs a native scene")
        if self.scratch is None:
            self.scratch = mujoco.MjData(env.model)
        mujoco.mj_copyData(self.scratch, env.model, env.data)
        slots = env.addresses.arm_slots
        return Privileged(
            model=env.model,
            data=self.scratch,
            objects=object_poses(env),
            arm_slots=tuple(int(s) for s in slots),
            arm_dofs=tuple(int(d) for d in env.addresses.qvel[slots]),
        )


def object_poses(env: NativeScene) -> dict[str, Pose]:
    """World pose of every object the scene file lists (its body ``scene_<name>``)."""
    options = env.scene.scene.options
    poses: dict[str, Pose] = {}
    for obj in options.objects if options and options.objects else []:
        body = mujoco.mj_name2id(env.model, mujoco.mjtObj.mjOBJ_BODY, f"scene_{obj.name}")
        poses[obj.name] = (env.data.xpos[body].copy(), env.data.xquat[body].copy())
    return poses
