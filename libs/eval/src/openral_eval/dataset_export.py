"""A sweep's episodes as one LeRobot v3.0 dataset (``openral sim sweep --dataset DIR``).

Each episode of the sweep keeps its steps in a staging folder
(:mod:`openral_eval.episode_frames`); once the sweep has run, :func:`export_dataset`
streams them, in the order of the plan (scene by scene, seed by seed), into
:func:`~openral_eval.lerobot_dataset.write_dataset`: ``observation.state`` is the joint
positions in manifest order and units, the other vectors the policy saw beside it by their
observation keys (``observation.velocity``, ``observation.tcp_pose``, the state sensors'
fields, ``observation.environment_state`` for a privileged policy; each value named), ``action``
the action as the env took it (in the
policy's action mode, e.g. ``ee_delta_pose``), ``next.success`` the scene's success after
the step, one video per camera that has a VLA slot (``observation.images.<slot>``), fps the
control rate, and the task text the scene file's ``task`` (else its id). Episodes that
ended in an error have nothing kept and are left out.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from openral_core.errors import OpenralError
from openral_core.loader import load_scene

from openral_eval.episode import EpisodeSpec, env_for, scene_for
from openral_eval.episode_frames import dataset_cameras, extra_names, load_episode
from openral_eval.lerobot_dataset import (
    DatasetEpisode,
    DatasetLayout,
    DatasetSummary,
    write_dataset,
)
from openral_eval.policies import make_policy
from openral_eval.policy import action_mode
from openral_eval.replay import PROVENANCE

STAGING = "dataset-episodes"
"""Folder under the sweep's ``--out`` where episodes keep their steps until the export."""


@dataclass(frozen=True)
class Exported:
    """What :func:`export_dataset` wrote, and the episodes it left out (they errored)."""

    summary: DatasetSummary
    left_out: int


def check_dataset_folder(folder: Path, robot: str, resume: bool) -> None:
    """Refuse a ``--dataset`` folder that exists, unless resuming a sweep of the same robot
    (the dataset is then rebuilt from every episode at the end).

    Raises:
        OpenralError: It exists without ``resume``, is not a LeRobot dataset, or holds
            another robot's episodes.
    """
    if not folder.exists():
        return
    if not resume:
        raise OpenralError(
            f"{folder} exists; add --resume to finish that sweep and rebuild it, or choose "
            "another --dataset"
        )
    info = folder / "meta" / "info.json"
    try:
        robot_type = json.loads(info.read_text())["robot_type"]
    except (OSError, ValueError, KeyError, TypeError):
        raise OpenralError(f"{folder} is not a LeRobot dataset (no readable {info})") from None
    if robot_type != robot:
        raise OpenralError(
            f"{folder} holds {robot_type} episodes; this sweep's robot is {robot}: choose "
            "another --dataset"
        )


def layout_of(spec: EpisodeSpec, mode: str) -> DatasetLayout:
    """The dataset's features for the sweep's first kept episode, whose policy acts in
    ``mode`` (every scene of a dataset has the same robot and the policy one action mode),
    and what else its policy saw (the episode's file names it)."""
    hal, robot = scene_for(spec.scene)
    env = env_for(spec, (), mode)
    return DatasetLayout(
        fps=1.0 / hal.control_period_s,
        robot_type=robot.name,
        state_names=hal.read_state().names,
        action_names=tuple(env.action_names),
        cameras=tuple(dataset_cameras(robot, hal.env.camera_names)),
        extra=extra_names(Path(spec.dataset)) if spec.dataset else {},
    )


def export_dataset(
    folder: Path, plan: Sequence[EpisodeSpec], staging: Path, digests: dict[tuple[str, int], str]
) -> Exported:
    """Write the kept episodes of ``plan`` as a LeRobot dataset at ``folder`` (replacing
    one a resumed sweep wrote before) with their origins in ``meta/openral.json``
    (``digests``: each (scene, seed)'s trajectory digest), then remove ``staging``.

    Raises:
        OpenralError: No episode kept anything (every one errored), or the dataset writer
            refused an episode (its reason).
    """
    kept = [spec for spec in plan if spec.dataset and Path(spec.dataset).is_file()]
    if not kept:
        raise OpenralError(f"no episode finished without an error: {folder} not written")
    tasks = {spec.scene: _task(spec.scene) for spec in kept}
    if folder.exists():  # checked by check_dataset_folder: a resumed sweep's own dataset
        shutil.rmtree(folder)
    mode = action_mode(make_policy(kept[0].policy, dict(kept[0].params)))
    summary = write_dataset(folder, layout_of(kept[0], mode), _episodes(kept, tasks))
    _write_provenance(folder, kept, mode, digests)
    shutil.rmtree(staging, ignore_errors=True)
    return Exported(summary, len(plan) - len(kept))


def _episodes(kept: Sequence[EpisodeSpec], tasks: dict[str, str]) -> Iterator[DatasetEpisode]:
    for spec in kept:
        assert spec.dataset is not None
        yield load_episode(Path(spec.dataset), tasks[spec.scene])


def _task(scene: str) -> str:
    """The scene file's ``task`` text, else its scene id."""
    described = load_scene(Path(scene))
    return described.task or described.scene.id


def _write_provenance(
    folder: Path, kept: Sequence[EpisodeSpec], mode: str, digests: dict[tuple[str, int], str]
) -> None:
    """``meta/openral.json``: per dataset episode, the scene, seed, policy, action ``mode``
    and the sweep's trajectory digest (what ``openral sim replay`` checks)."""
    episodes = [
        {
            "episode_index": index,
            "scene": spec.scene,
            "seed": spec.seed,
            "policy": spec.policy,
            "params": dict(spec.params),
            "action_mode": mode,
            "trajectory_sha256": digests.get((spec.scene, spec.seed), ""),
        }
        for index, spec in enumerate(kept)
    ]
    text = json.dumps({"format": 1, "episodes": episodes}, indent=1) + "\n"
    (folder / PROVENANCE).write_text(text)
