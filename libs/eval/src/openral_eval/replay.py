"""Replay one episode of a dataset a sweep wrote, and check it is the episode that ran.

A sweep with ``--dataset`` stores, beside the LeRobot files, where each episode came from
(``meta/openral.json``: scene, seed, policy, action mode, the sweep's trajectory digest).
:func:`replay` resets that scene with that seed and steps the env with the dataset's own
``action`` column, as a trainer reads it (the sweep applied those float32 values, so they
are exact), hashing every joint position as the sweep's episode does. A matching digest
means the dataset's actions reproduce the run joint for joint. A sweep's results without a
dataset replay too (:func:`replay_sweep`): the policy runs again from the line's seed.
``video`` renders the replay's first camera to an MP4 and ``view`` (given the replay's HAL,
it returns a browser view's feed) sees every step; both render the scene's cameras, which
changes no joint.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from openral_core.errors import OpenralError
from openral_hal.sim_attached import SimAttachedHAL

from openral_eval.env_actions import ActionMode
from openral_eval.episode import StepWatch, camera_rate_hz, close_scenes, run_episode, scene_for
from openral_eval.lerobot_dataset import DATA_PATH
from openral_eval.results import read_results, spec_of
from openral_eval.scene_env import EnvConfig, SceneEnv
from openral_eval.video import VideoWriter

PROVENANCE = Path("meta") / "openral.json"
"""Where a dataset says which scene, seed and policy each episode came from."""


@dataclass(frozen=True)
class Replayed:
    """One replayed episode: its origin, steps, and both trajectory digests."""

    scene: str
    seed: int
    steps: int
    digest: str
    expected: str
    frames: int = 0
    """Frames written to the video (0: no video)."""

    @property
    def matches(self) -> bool:
        """The replay moved every joint exactly as the sweep's episode did."""
        return self.digest == self.expected


def provenance(dataset: Path) -> list[dict[str, object]]:
    """The per-episode origins a sweep wrote into ``dataset``.

    Raises:
        OpenralError: ``dataset`` has no readable ``meta/openral.json`` (not written by
            ``openral sim sweep --dataset``).
    """
    path = dataset / PROVENANCE
    try:
        episodes: list[dict[str, object]] = json.loads(path.read_text())["episodes"]
    except (OSError, ValueError, KeyError, TypeError):
        raise OpenralError(
            f"{path}: missing or unreadable; expected a dataset written by "
            "`openral sim sweep --dataset` (or a sweep's folder with its episodes.jsonl)"
        ) from None
    return episodes


def replay(
    dataset: Path,
    index: int,
    *,
    video: Path | None = None,
    view: Callable[[SimAttachedHAL], StepWatch] | None = None,
) -> Replayed:
    """Replay episode ``index`` of ``dataset`` (see the module doc).

    Raises:
        OpenralError: No such episode, or the dataset lacks its provenance.
    """
    episodes = provenance(dataset)
    if not 0 <= index < len(episodes):
        raise OpenralError(f"--episode {index}: {dataset} holds episodes 0 to {len(episodes) - 1}")
    origin = episodes[index]
    data = pq.read_table(
        dataset / DATA_PATH.format(chunk_index=0, file_index=0),
        columns=["episode_index", "action"],
    )
    mine = np.asarray(data.column("episode_index").to_numpy()) == index
    actions = np.asarray(data.column("action").to_pylist(), dtype=np.float32)[mine]
    scene, seed = str(origin["scene"]), int(str(origin["seed"]))
    mode = ActionMode(str(origin["action_mode"]))
    sensors: bool | tuple[str, ...] = video is not None or view is not None or ()
    config = EnvConfig(scene, sensors=sensors, max_steps=len(actions) + 1, action_mode=mode)
    env = SceneEnv(config)
    camera = next(iter(env.hal.env.camera_names), None) if video is not None else None
    fps = camera_rate_hz(env.hal, env.robot, camera)
    writer = VideoWriter(video, camera, fps) if camera is not None else VideoWriter(None, None, 1)
    try:
        watch = view(env.hal) if view is not None else None
        digest = _digest(env, seed, actions, _Watchers(writer, watch))
    finally:
        writer.close()
        env.close()
    expected = str(origin["trajectory_sha256"])
    return Replayed(scene, seed, len(actions), digest, expected, writer.frames)


def replay_sweep(
    results: Path,
    index: int,
    *,
    video: Path | None = None,
    view: Callable[[SimAttachedHAL], StepWatch] | None = None,
) -> Replayed:
    """Replay line ``index`` of a sweep's ``results/episodes.jsonl``: its policy again from
    its seed, limited to the steps it took (a sweep keeps no actions; episodes are pure
    functions of their line), compared with the line's digest.

    Raises:
        OpenralError: No such line, or its episode ended with an error.
    """
    lines = read_results(results / "episodes.jsonl")
    if not 0 <= index < len(lines):
        raise OpenralError(f"--episode {index}: {results} holds episodes 0 to {len(lines) - 1}")
    line = lines[index]
    if line.get("error") is not None:
        raise OpenralError(f"--episode {index} ended with an error in the sweep: {line['error']}")
    spec = spec_of(line, video=None if video is None else str(video))
    try:
        watch = view(scene_for(spec.scene)[0]) if view is not None else None
        result = run_episode(spec, watch)
    finally:
        close_scenes()
    if result.error is not None:
        raise OpenralError(f"--episode {index}: the replay ended with an error: {result.error}")
    expected = str(line["trajectory_sha256"])
    return Replayed(spec.scene, spec.seed, result.steps, result.trajectory_sha256, expected)


class _Watchers:
    """The video and the view, after the reset and after each step."""

    def __init__(self, video: VideoWriter, watch: StepWatch | None) -> None:
        self.video, self.watch = video, watch

    def __call__(self, env: SceneEnv, action: np.ndarray | None) -> None:
        self.video.add(env.hal.last_observation())
        if self.watch is not None:
            named = (
                None
                if action is None
                else dict(zip(env.action_names, action.tolist(), strict=True))
            )
            self.watch(named)


def _digest(env: SceneEnv, seed: int, actions: np.ndarray, watchers: _Watchers) -> str:
    """The trajectory digest of stepping ``actions`` from the reset of ``seed``: every
    joint position before each step, then the last (as a sweep's episode hashes them)."""
    digest = hashlib.sha256()
    env.reset(seed=seed)
    watchers(env, None)
    for action in actions:
        digest.update(env.hal.read_state().positions.tobytes())
        applied = action.astype(np.float64)
        env.step(applied)
        watchers(env, applied)
    digest.update(env.hal.read_state().positions.tobytes())
    return digest.hexdigest()
