"""``openral sim sweep``: a policy over scenes and seeds, with success rates and intervals.

Example::

    openral sim sweep --config robots/franka_panda/scenes/tabletop.yaml --seeds 0:20 \\
        --policy scripted_lift --out o/

Writes ``o/episodes.jsonl`` (one line per episode: scene, seed, policy, params, success,
steps, sim time, wall time, error, trajectory digest, video) and ``o/summary.json``, and
prints each scene's success rate with its 95 % Wilson interval. Videos go to
``o/videos/``.
"""

from __future__ import annotations

import json
import os
import time
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from openral_core.errors import OpenralError

from openral_cli.commands.sweep_dataset import dataset_staging, export
from openral_cli.console import err, out, progress
from openral_cli.help_text import PARAM_HELP

if TYPE_CHECKING:
    from openral_eval.episode import EpisodeResult, EpisodeSpec
    from openral_eval.results import EpisodeLog

VIDEO_CHOICES = ("first", "failures", "all", "none")
EPISODE_TIMEOUT_S = 600.0
"""Default wall-time limit of one episode (``--episode-timeout``) [s]."""
MAX_EPISODES = 100_000
DatasetFolder = Annotated[
    Path | None,
    typer.Option(
        "--dataset",
        help="Also write the episodes as a LeRobot v3.0 dataset in this new folder.",
        show_default=False,
    ),
]


def parse_seeds(text: str) -> list[int]:
    """``0:100`` (start:stop, stop excluded), ``7``, or ``1,5,9``.

    Raises:
        typer.BadParameter: Anything else, an empty range, or over :data:`MAX_EPISODES`.
    """
    try:
        if ":" in text:
            start, stop = (int(part) for part in text.split(":", 1))
            if stop <= start:
                message = f"{text!r} is an empty range: STOP must be greater than START"
                raise typer.BadParameter(message, param_hint="--seeds")
            if stop - start > MAX_EPISODES:
                raise typer.BadParameter(f"at most {MAX_EPISODES} seeds", param_hint="--seeds")
            seeds = list(range(start, stop))
        else:
            seeds = [int(part) for part in text.split(",")]
    except ValueError:
        raise typer.BadParameter(
            f"{text!r}: expected START:STOP (0:100), a seed (7) or a list (1,5,9)",
            param_hint="--seeds",
        ) from None
    if min(seeds) < 0:
        raise typer.BadParameter(f"{text!r} gives a negative seed", param_hint="--seeds")
    repeated = sorted(seed for seed, count in Counter(seeds).items() if count > 1)
    if repeated:
        message = f"{text!r} gives seed {repeated[0]} more than once; each seed runs once"
        raise typer.BadParameter(message, param_hint="--seeds")
    return seeds


def check_distinct_scenes(config: list[Path]) -> None:
    """Refuse a scene file given twice (also by another spelling of its path).

    Raises:
        typer.BadParameter: Naming the first file given more than once.
    """
    seen: set[Path] = set()
    for path in config:
        if path.resolve() in seen:
            message = f"{path} is given more than once; each scene runs once"
            raise typer.BadParameter(message, param_hint="--config")
        seen.add(path.resolve())


def check_out_dir(out_dir: Path) -> None:
    """Refuse an ``--out`` that could not hold the results, before anything runs and
    without making it (a refused sweep leaves no folder behind).

    Raises:
        typer.BadParameter: ``out_dir`` or a folder above it is a file, or the folder that
            would hold it cannot be written to.
    """
    for path in (out_dir, *out_dir.parents):
        if not path.exists():
            continue
        if not path.is_dir():
            where = "is a file" if path == out_dir else f"is under {path}, which is a file"
            raise typer.BadParameter(
                f"{out_dir} {where}; expected a folder (made if missing)", param_hint="--out"
            )
        if not os.access(path, os.W_OK | os.X_OK):
            raise typer.BadParameter(f"{out_dir}: cannot write in {path}", param_hint="--out")
        return


def sweep(
    config: Annotated[
        list[Path], typer.Option("--config", help="Scene file (repeat for several scenes).")
    ],
    seeds: Annotated[str, typer.Option("--seeds", help="START:STOP, a seed, or 1,5,9.")],
    policy: Annotated[str, typer.Option("--policy", help="Policy name (registered).")],
    out_dir: Annotated[Path, typer.Option("--out", help="Directory for the results.")],
    params: Annotated[list[str] | None, typer.Option("--param", "-p", help=PARAM_HELP)] = None,
    steps: Annotated[
        int | None, typer.Option("--steps", min=1, help="Step limit (default: the scene's).")
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", min=1, max=512, help="Local processes.")
    ] = None,
    ray: Annotated[
        str | None,
        typer.Option("--ray", help="Run on Ray: alone, a local instance; or a cluster ADDRESS."),
    ] = None,
    video: Annotated[
        str, typer.Option("--video", help="MP4s of the first camera: first|failures|all|none.")
    ] = "first",
    resume: Annotated[
        bool, typer.Option("--resume", help="Keep finished episodes, run the rest.")
    ] = False,
    episode_timeout: Annotated[
        float,
        typer.Option("--episode-timeout", min=0.001, help="Wall-time limit of one episode [s]."),
    ] = EPISODE_TIMEOUT_S,
    dataset: DatasetFolder = None,
) -> None:
    """Run POLICY on every (scene, seed) episode through the same HAL contract as deploy
    sim, in parallel; write ``episodes.jsonl`` and ``summary.json`` and print each scene's
    success rate with its 95 % Wilson interval. Exits 1 when every episode failed with an
    error."""
    from openral_eval.policies import parse_params
    from openral_eval.ray_session import check_ray_address

    _check_arguments(config, out_dir, video)
    pairs = tuple(sorted(parse_params(params or []).items()))
    _check_policy(policy, pairs, config)
    if ray not in (None, "local"):
        check_ray_address(ray)  # before the results file is touched
    staging = None if dataset is None else dataset_staging(config, dataset, (out_dir, resume, ray))
    plan = _plan(config, parse_seeds(seeds), policy, pairs, steps, (video, out_dir, staging))
    log = _open_log(out_dir / "episodes.jsonl", resume=resume)
    where = (workers or os.cpu_count() or 1, ray, episode_timeout)
    clock = SweepClock()
    _run_plan(plan, log, where, video, out_dir, clock)
    lines = log.sort(plan)
    _report(lines, policy, out_dir, clock)
    if dataset is not None:
        export(dataset, plan, out_dir, lines)


def _check_policy(policy: str, pairs: tuple[tuple[str, str], ...], config: list[Path]) -> None:
    """Build the policy once and check it fits every scene: a bad name, parameter, mode or
    need stops the sweep here, before any episode (exit 2). A policy server that is down
    now is said in one line; each episode then says so too, and the sweep goes on."""
    from openral_eval.policies import make_policy
    from openral_eval.policy import PolicyConfigError
    from openral_eval.policy_fit import check_policy_fits
    from openral_eval.remote_policy import PolicyServerError, RemotePolicy

    built: object = None
    try:
        built = make_policy(policy, dict(pairs))
        for path in config:
            _build_scene(path)
            check_policy_fits(built, policy, str(path))
    except PolicyConfigError as error:
        raise typer.BadParameter(str(error), param_hint="--policy") from None
    except PolicyServerError as error:  # down now: each episode says so, the sweep goes on
        err.print(f"[yellow]{error}: its fit to the scenes is not checked[/yellow]")
    finally:  # a served policy's connection (each episode opens its own)
        if isinstance(built, RemotePolicy):
            built.close()


def _check_arguments(config: list[Path], out_dir: Path, video: str) -> None:
    """Refuse a bad ``--video``, ``--out`` or repeated ``--config`` before anything runs."""
    if video not in VIDEO_CHOICES:
        raise typer.BadParameter(
            f"expected one of {', '.join(VIDEO_CHOICES)}", param_hint="--video"
        )
    check_out_dir(out_dir)
    check_distinct_scenes(config)


def _run_plan(
    plan: list[EpisodeSpec],
    log: EpisodeLog,
    where: tuple[int, str | None, float],
    video: str,
    out_dir: Path,
    clock: SweepClock,
) -> None:
    """Run the episodes of ``plan`` that ``log`` does not hold yet (see :func:`_run`); on
    Ctrl-C say how many are written and exit 130."""
    done = log.done()
    todo = [spec for spec in plan if spec.key not in done]
    try:
        run_episodes(todo, (len(plan) - len(todo), len(plan)), where, log, video, out_dir, clock)
    except KeyboardInterrupt:
        err.print(
            f"interrupted: {len(log.done())} of {len(plan)} episodes are in {log.path}; the "
            "same command with --resume runs the rest",
            markup=False,
        )
        raise typer.Exit(130) from None


def _open_log(path: Path, *, resume: bool) -> EpisodeLog:
    """The results file, started (kept whole with ``resume``; refused if it holds results
    and ``resume`` is not given)."""
    from openral_eval.results import EpisodeLog

    log = EpisodeLog(path)
    if log.path.exists() and log.path.stat().st_size and not resume:
        raise OpenralError(
            f"{log.path} already holds results: add --resume to finish that sweep, or "
            "choose another --out"
        )
    log.start(resume=resume)
    return log


class SweepClock:
    """When (``time.perf_counter``) a sweep started handing out episodes, when its workers
    were ready, and when its last result was written [s]."""

    def __init__(self) -> None:
        self.ready: float | None = None
        self.last_written: float | None = None
        self.start()

    def start(self) -> None:
        self.started = time.perf_counter()

    def mark_ready(self) -> None:
        self.ready = time.perf_counter()

    def mark_written(self) -> None:
        self.last_written = time.perf_counter()

    def times(self) -> dict[str, float]:
        """``run_wall_s`` (start to last result), split into ``startup_s`` (start to ready)
        and ``episodes_wall_s`` (ready to last result), in seconds."""
        end = self.last_written or time.perf_counter()
        ready = min(self.ready or self.started, end)
        return {
            "run_wall_s": round(end - self.started, 3),
            "startup_s": round(ready - self.started, 3),
            "episodes_wall_s": round(end - ready, 3),
        }


def _build_scene(path: Path) -> None:
    """Load and build the scene now, before the sweep's clock starts: a bad file is one
    located error before any episode, and episodes run in this process or in workers
    forked from it find the scene built (Ray's workers build their own)."""
    from openral_eval.episode import scene_for

    scene_for(str(path))


def _plan(
    config: list[Path],
    seeds: list[int],
    policy: str,
    pairs: tuple[tuple[str, str], ...],
    steps: int | None,
    files: tuple[str, Path, Path | None],
) -> list[EpisodeSpec]:
    """Every episode, scene by scene, seed by seed, with the files it writes: ``files`` is
    (``--video``, ``--out``, the folder where episodes keep their steps for a dataset or
    None); its video path, if it is filmed, and its dataset steps, if kept."""
    from openral_eval.episode import EpisodeSpec

    video, out_dir, staging = files
    if len(config) * len(seeds) > MAX_EPISODES:
        raise typer.BadParameter(f"at most {MAX_EPISODES} episodes", param_hint="--seeds")
    plan = []
    for path in config:
        for index, seed in enumerate(seeds):
            wanted = video in ("all", "failures") or (video == "first" and index == 0)
            movie = str(out_dir / "videos" / f"{episode_slug(path, seed)}.mp4") if wanted else None
            kept = None if staging is None else kept_steps(staging, path, seed)
            plan.append(EpisodeSpec(str(path), seed, policy, pairs, steps, movie, kept))
    return plan


def episode_slug(scene: Path | str, seed: int) -> str:
    """An episode's file name stem: the scene path's last three parts, then the seed."""
    slug = "_".join(Path(scene).with_suffix("").parts[-3:]).replace(".", "")
    return f"{slug}_seed{seed}"


def kept_steps(staging: Path, scene: Path | str, seed: int) -> str:
    """Where an episode of a dataset sweep keeps its steps until the export."""
    return str(staging / f"{episode_slug(scene, seed)}.npz")


def run_episodes(
    todo: list[EpisodeSpec],
    counts: tuple[int, int],
    where: tuple[int, str | None, float],
    log: EpisodeLog,
    video: str,
    out_dir: Path,
    clock: SweepClock,
) -> None:
    """Run ``todo`` with a progress bar; every result is written as it arrives (and
    ``clock`` marks when the workers were ready and when the last result was written).

    ``counts`` is (episodes already done, episodes in all); ``where`` (workers, Ray
    address or None, an episode's wall-time limit [s])."""
    already, total = counts
    workers, ray, timeout_s = where
    from dataclasses import replace

    from openral_eval.sweep import run_pool, run_ray

    with progress() as bar:
        task = bar.add_task("episodes", total=total, completed=already)
        wins = [0]

        def record(result: EpisodeResult) -> None:
            if video == "failures" and result.success and result.video:
                Path(result.video).unlink(missing_ok=True)
                result = replace(result, video=None)
            if result.video:  # as the directory's own path, whichever --out named it
                result = replace(result, video=str(Path(result.video).relative_to(out_dir)))
            log.append(result)
            clock.mark_written()
            wins[0] += int(result.success)
            bar.update(task, advance=1, description=f"episodes · {wins[0]} succeeded")

        clock.start()
        if ray is not None:
            run_ray(todo, ray, workers, record, clock.mark_ready, timeout_s)
        elif todo:  # even one worker is a process of its own: a policy's crash costs only
            # its episode (sys.exit, a segfault), and a hung one its time limit
            run_pool(todo, min(workers, len(todo)), record, clock.mark_ready, timeout_s)


def _report(lines: list[dict[str, object]], policy: str, out_dir: Path, clock: SweepClock) -> None:
    """The per-scene table, ``summary.json`` (with the :meth:`SweepClock.times`: the
    workers' start counts in ``run_wall_s``, their shutdown not) and where everything is."""
    from openral_eval.summary import summarise, summary_json
    from rich.table import Table

    rows = summarise(lines)
    summary = {**summary_json(rows, policy), **clock.times()}
    (out_dir / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    table = Table(title=f"{policy}: success rate per scene (95 % Wilson interval)")
    for column in ("scene", "episodes", "success", "rate", "95 % interval", "mean steps", "errors"):
        table.add_column(column, justify="left" if column == "scene" else "right")
    for row in rows:
        interval = f"{row.ci95_low:.2f} to {row.ci95_high:.2f}"
        table.add_row(
            row.scene,
            str(row.episodes),
            str(row.successes),
            f"{row.success_rate:.2f}",
            interval,
            f"{row.mean_steps:.0f}",
            str(row.errors),
        )
    out.print(table)
    errors = [line for line in lines if line.get("error")]
    if errors:
        first = errors[0]
        out.print(f"first error (seed {first['seed']}): {first['error']}", markup=False)
    out.print(
        f"wrote {out_dir / 'episodes.jsonl'} ({len(lines)} episodes) and {out_dir / 'summary.json'}"
    )
    if lines and len(errors) == len(lines):
        err.print(
            f"every episode failed ({len(lines)} of {len(lines)}); see {out_dir}", markup=False
        )
        raise typer.Exit(1)
