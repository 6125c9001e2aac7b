"""``openral sim export RESULTS DATASET``: a finished sweep's episodes as a LeRobot dataset.

A sweep without ``--dataset`` keeps no frames, only each episode's line in
``episodes.jsonl`` (scene, seed, policy, parameters, steps, trajectory digest). Episodes
are pure functions of those, so the export runs each episode that ended without an error
again, limited to the steps it took, keeping its steps as ``sim sweep --dataset`` does, and
writes the same dataset such a sweep would have. Each rerun must give the digest the sweep
recorded; one that does not (the scene, the policy or openral changed since) stops the
export before anything is written.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Annotated

import typer
from openral_core.errors import OpenralError

from openral_cli.commands.sweep import (
    EPISODE_TIMEOUT_S,
    SweepClock,
    kept_steps,
    run_episodes,
)
from openral_cli.commands.sweep_dataset import dataset_staging, export
from openral_cli.console import out

WORK = ".export"
"""The folder under RESULTS where the export's reruns write, removed when it is done."""


def sim_export(
    results: Annotated[Path, typer.Argument(help="A sweep's --out folder (its episodes.jsonl).")],
    dataset: Annotated[Path, typer.Argument(help="The dataset folder to write (new).")],
    workers: Annotated[
        int | None, typer.Option("--workers", min=1, max=512, help="Local processes.")
    ] = None,
) -> None:
    """Write the episodes of a finished sweep in RESULTS as a LeRobot v3.0 dataset in
    DATASET, rerunning each from its seed (the digest must match the sweep's).

    Example:

        openral sim export o/lift o/lift_ds
    """
    lines = _finished(results / "episodes.jsonl")
    scenes = sorted({Path(str(line["scene"])) for line in lines})
    work = results / WORK
    shutil.rmtree(work, ignore_errors=True)
    staging = dataset_staging(scenes, dataset, (work, False, None))
    from openral_eval.results import EpisodeLog, spec_of

    plan = [
        spec_of(line, dataset=kept_steps(staging, str(line["scene"]), int(str(line["seed"]))))
        for line in lines
    ]

    try:
        log = EpisodeLog(work / "episodes.jsonl")
        log.start(resume=False)
        where = (workers or os.cpu_count() or 1, None, EPISODE_TIMEOUT_S)
        run_episodes(plan, (0, len(plan)), where, log, "none", work, SweepClock())
        rerun = log.sort(plan)
        _check_digests(lines, rerun)
        export(dataset, plan, work, rerun)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _finished(path: Path) -> list[dict[str, object]]:
    """The lines of ``path`` whose episode ended without an error, all of one policy.

    Raises:
        OpenralError: An unreadable file or line, no finished episode, several policies.
    """
    from openral_eval.results import read_results

    lines = [line for line in read_results(path) if line.get("error") is None]
    policies = sorted({str(line["policy"]) for line in lines})
    if not lines:
        raise OpenralError(f"{path}: no episode ended without an error; nothing to export")
    if len(policies) > 1:
        raise OpenralError(f"{path}: episodes of several policies ({', '.join(policies)})")
    return lines


def _check_digests(lines: list[dict[str, object]], rerun: list[dict[str, object]]) -> None:
    """Refuse an export whose reruns are not the sweep's episodes."""
    before = {(str(r["scene"]), int(str(r["seed"]))): r["trajectory_sha256"] for r in lines}
    for line in rerun:
        key = (str(line["scene"]), int(str(line["seed"])))
        if line.get("error") is not None or line["trajectory_sha256"] != before[key]:
            why = line.get("error") or "its trajectory differs from the sweep's"
            raise OpenralError(
                f"{key[0]} seed {key[1]} did not rerun as the sweep ran it ({why}); the scene, "
                "the policy or openral changed since: run the sweep again with --dataset"
            )
    out.print(f"{len(rerun)} episodes rerun, each as the sweep ran it", markup=False)
