"""Replay one episode of a dataset a sweep wrote, and check it is the episode that ran.

A sweep with ``--dataset`` stores, beside the LeRobot files, where each episode came from
(``meta/openral.json``: scene, seed, policy, action mode, the sweep's trajectory digest).
:func:`replay` resets that scene with that seed and steps the env with the dataset's own
``action`` column, as a trainer reads it (the sweep applied those float32 values, so they
are exact), hashing every joint position as the sweep's episode does. A matching digest
means the dataset's actions reproduce the run joint for joint.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from openral_core.errors import OpenralError

from openral_eval.env_actions import ActionMode
from openral_eval.lerobot_dataset import DATA_PATH
from openral_eval.scene_env import EnvConfig, SceneEnv

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
            "`openral sim sweep --dataset`"
        ) from None
    return episodes


def replay(dataset: Path, index: int) -> Replayed:
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
    config = EnvConfig(scene, sensors=(), max_steps=len(actions) + 1, action_mode=mode)
    env = SceneEnv(config)
    try:
        digest = _digest(env, seed, actions)
    finally:
        env.close()
    return Replayed(scene, seed, len(actions), digest, str(origin["trajectory_sha256"]))


def _digest(env: SceneEnv, seed: int, actions: np.ndarray) -> str:
    """The trajectory digest of stepping ``actions`` from the reset of ``seed``: every
    joint position before each step, then the last (as a sweep's episode hashes them)."""
    digest = hashlib.sha256()
    env.reset(seed=seed)
    for action in actions:
        digest.update(env.hal.read_state().positions.tobytes())
        env.step(action.astype(np.float64))
    digest.update(env.hal.read_state().positions.tobytes())
    return digest.hexdigest()
