"""A fuzz campaign: ``python -m tests.fuzz.campaign N [--seed S] [--workers K] [--out DIR]``.

Draws N cases (case ``i`` depends only on the seed and ``i``), runs them on K worker
processes through the real stages (:mod:`tests.fuzz.stages`), then prints the counts by
outcome and stage and every distinct finding with a saved reproducer. Exits 1 when any
case was a traceback, hang, crash or unlocated refusal. ``just fuzz N`` runs this.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from tests.fuzz.cases import CaseSpec, draw_case, write_case
from tests.fuzz.outcome import FINDINGS
from tests.fuzz.pool import PoolError, run_pool
from tests.fuzz.report import Report
from tests.fuzz.stages import Case

Ticket = tuple[int, CaseSpec, Path]
console = Console(soft_wrap=True)


def _arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog="just fuzz", description="Fuzz manifests and scenes through the real stages."
    )
    parser.add_argument("cases", type=int, help="number of cases to run")
    parser.add_argument("--seed", type=int, default=0, help="campaign seed (default 0)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("fuzz-findings"),
        help="folder for reproducers and summary.json (default fuzz-findings/)",
    )
    args = parser.parse_args(argv)
    if args.cases < 1 or args.workers < 1:
        parser.error("cases and workers must be at least 1")
    return args


def _jobs(seed: int, count: int, work: Path) -> Iterator[tuple[Ticket, Case]]:
    for index in range(count):
        spec = draw_case(seed, index)
        folder = work / f"case-{index}"
        folder.mkdir()
        yield (index, spec, folder), write_case(spec, folder)


def run_campaign(count: int, seed: int, workers: int, out: Path) -> Report:
    """Run ``count`` cases on ``workers`` processes; return the filled :class:`Report`."""
    out.mkdir(parents=True, exist_ok=True)
    report = Report(out.resolve(), seed)
    report.clear()
    work = Path(tempfile.mkdtemp(prefix="openral-fuzz-"))
    columns = (
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("findings: {task.fields[findings]}"),
    )
    try:
        with Progress(*columns, console=console) as progress:
            task = progress.add_task("fuzzing", total=count, findings=0)
            for (index, spec, folder), result in run_pool(_jobs(seed, count, work), workers, work):
                report.add(index, spec, folder, result)
                shutil.rmtree(folder, ignore_errors=True)
                found = sum(f.count for f in report.findings.values())
                progress.update(task, advance=1, findings=found)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return report


def main(argv: list[str] | None = None) -> int:
    """Run a campaign from the command line; the exit code (0, or 1 on findings)."""
    args = _arguments(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")
    start = time.monotonic()
    try:
        report = run_campaign(args.cases, args.seed, args.workers, args.out)
    except PoolError as error:
        console.print(f"[red]{error}[/]")
        return 2
    minutes = (time.monotonic() - start) / 60
    console.print(report.outcome_table())
    if report.failed:
        console.print("\n[bold]findings[/] (one reproducer each; the lowest case index)")
        console.print(report.findings_text(), markup=False, highlight=False)
    summary = report.write_summary()
    kinds = ", ".join(sorted(o.value for o in FINDINGS))
    verdict = "[red]findings[/]" if report.failed else "[green]no findings[/]"
    seconds, index = report.slowest
    console.print(
        f"{args.cases} cases, seed {args.seed}, {args.workers} workers, {minutes:.1f} min, "
        f"slowest case {seconds:.1f} s (#{index}): {verdict} ({kinds}); summary in {summary}"
    )
    return 1 if report.failed else 0


if __name__ == "__main__":
    sys.exit(main())
