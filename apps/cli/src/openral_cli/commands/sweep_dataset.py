"""``openral sim sweep --dataset DIR``: checked before anything runs; the plan's episodes
keep their steps, and the sweep ends by writing them as one LeRobot v3.0 dataset
(:mod:`openral_eval.dataset_export`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from openral_cli.console import out

if TYPE_CHECKING:
    from openral_eval.episode import EpisodeSpec


def dataset_staging(config: list[Path], dataset: Path, run: tuple[Path, bool, str | None]) -> Path:
    """Check ``--dataset`` (a local sweep, one robot, a folder that is new or this sweep's
    own when resuming) and return the folder where episodes keep their steps until the
    export; ``run`` is (``--out``, ``--resume``, ``--ray``)."""
    from openral_core.loader import load_scene, scene_folder_robot
    from openral_eval.dataset_export import STAGING, check_dataset_folder

    out_dir, resume, ray = run
    if ray not in (None, "local"):
        message = "episodes on a Ray cluster keep their steps on its machines; run locally"
        raise typer.BadParameter(message, param_hint="--dataset")
    robots = sorted({load_scene(p).robot_id or scene_folder_robot(p) or "?" for p in config})
    if len(robots) > 1:
        raise typer.BadParameter(
            f"a dataset holds one robot; these scenes have {', '.join(robots)}",
            param_hint="--dataset",
        )
    check_dataset_folder(dataset, robots[0], resume)
    return out_dir / STAGING


def export(
    dataset: Path, plan: list[EpisodeSpec], out_dir: Path, lines: list[dict[str, object]]
) -> None:
    """Write the dataset from the kept episodes (``lines``: the sweep's results, for their
    trajectory digests) and say what it holds."""
    from openral_eval.dataset_export import STAGING, export_dataset

    digests = {(str(r["scene"]), int(str(r["seed"]))): str(r["trajectory_sha256"]) for r in lines}
    exported = export_dataset(dataset, plan, out_dir / STAGING, digests)
    summary = exported.summary
    left = f"; {exported.left_out} episodes with an error left out" if exported.left_out else ""
    out.print(
        f"wrote {dataset} (LeRobot v3.0: {summary.episodes} episodes, {summary.frames} frames, "
        f"{summary.tasks} tasks{left})",
        markup=False,
    )
