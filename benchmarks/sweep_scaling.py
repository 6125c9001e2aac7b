"""Sweep scaling on this machine: one process, a pool of two, and Ray with two CPUs.

Each workload runs as ``openral sim sweep`` three times (``--workers 1``, ``--workers 2``,
``--workers 2 --ray``) on the franka tabletop without videos. The time compared is the
sweep's own ``run_wall_s`` (``summary.json``): from the first episode handed out to the
last result written, so the pool's forks and Ray's start-up count, the command's imports
(the same for all three) and the workers' shutdown do not. Workloads:

- ``cameras``: ``wave`` observing its two camera slots, 200 steps, seeds 0:40 (two frames
  rendered per step, as a VLA observes: ~6 s per episode, ~2 minutes on two cores);
- ``lift``: ``scripted_lift`` over seeds 0:20 (the issue's sweep; ~60 steps,
  about a second on two cores; ~60-90 ms an episode).

The same run also times Ray's fixed cost alone: a Ray session that starts, runs one empty
task per CPU and ends, as ``openral sim sweep --ray`` starts it. A sweep shorter than a
few times that cannot be within 15 % on Ray, whatever the episodes.

Targets: ``--workers 2`` ≥ 1.7 x ``--workers 1`` on 2 cores; Ray within 15 % of
``--workers 2`` on a sweep that runs minutes (``cameras``). The three ``episodes.jsonl`` of
a workload must be identical but for wall times. Run with ``just bench-sweep``
(``--workload lift`` for the quick one).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

from openral_core.paths import repo_root
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results

SCENE = "robots/franka_panda/scenes/tabletop.yaml"
WORKLOADS = {
    "cameras": ("--policy", "wave", "--steps", "200"),
    "lift": ("--policy", "scripted_lift"),
}
SEEDS = {"cameras": "0:40", "lift": "0:20"}
RAY_ALONE = """
import time
from openral_eval.sweep import ray_session
started = time.perf_counter()
with ray_session("local", 2) as ray:
    ray.get([ray.remote(num_cpus=1)(lambda: 0).remote() for _ in range(2)])
    print(time.perf_counter() - started)
"""
RUNS = {
    "workers 1": ("--workers", "1"),
    "workers 2": ("--workers", "2"),
    "ray": ("--workers", "2", "--ray"),
}
POOL_TARGET, RAY_TARGET = 1.7, 0.15


def timed(workload: str, run: str, seeds: str, out: Path) -> tuple[float, list[dict[str, object]]]:
    """The sweep's ``run_wall_s`` and its lines without wall times."""
    folder = out / workload / run.replace(" ", "_")
    command = [str(Path(sys.executable).parent / "openral"), "sim", "sweep", "--config", SCENE]
    command += ["--seeds", seeds, "--video", "none", "--out", str(folder)]
    command += [*WORKLOADS[workload], *RUNS[run]]
    done = subprocess.run(command, capture_output=True, text=True, cwd=repo_root(), check=False)
    if done.returncode != 0:
        raise SystemExit(f"{workload} / {run} failed:\n{done.stderr}")
    seconds = float(json.loads((folder / "summary.json").read_text())["run_wall_s"])
    lines = [json.loads(line) for line in (folder / "episodes.jsonl").read_text().splitlines()]
    return seconds, [{k: v for k, v in line.items() if k != "wall_time_s"} for line in lines]


def ray_alone_s() -> float:
    """Ray's fixed cost: start, one empty task per CPU, as the sweep starts it [s]."""
    done = subprocess.run(
        [sys.executable, "-c", RAY_ALONE], capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise SystemExit(f"Ray alone failed:\n{done.stderr}")
    return float(done.stdout.split()[-1])


def measure(workload: str, seeds: str, ray_s: float, console: Console) -> dict[str, object]:
    """Run one workload three ways; print its table; its results."""
    seconds: dict[str, float] = {}
    files: dict[str, list[dict[str, object]]] = {}
    with tempfile.TemporaryDirectory() as folder, console.status("sweeping") as status:
        for run in RUNS:
            status.update(f"{workload}: {run}")
            seconds[run], files[run] = timed(workload, run, seeds, Path(folder))
    episodes = len(files["workers 1"])
    table = Table(
        title=f"{workload}: {' '.join(WORKLOADS[workload])}, seeds {seeds} ({episodes} "
        f"episodes), {os.cpu_count()} cores"
    )
    for column in ("run", "sweep s", "episodes/s", "vs workers 1", "vs workers 2"):
        table.add_column(column, justify="left" if column == "run" else "right")
    for run in RUNS:
        table.add_row(
            run,
            f"{seconds[run]:.2f}",
            f"{episodes / seconds[run]:.2f}",
            f"{seconds['workers 1'] / seconds[run]:.2f}x",
            f"{seconds[run] / seconds['workers 2'] - 1.0:+.0%}",
        )
    table.add_row("Ray alone (no episode)", f"{ray_s:.2f}", "", "", "")
    console.print(table)
    speedup = seconds["workers 1"] / seconds["workers 2"]
    over = seconds["ray"] / seconds["workers 2"] - 1.0
    identical = files["workers 1"] == files["workers 2"] == files["ray"]
    console.print(_verdict(speedup, over, ray_s / seconds["workers 2"], identical))
    return {
        "seeds": seeds,
        "episodes": episodes,
        "run_wall_s": seconds,
        "ray_alone_s": ray_s,
        "pool_speedup": speedup,
        "ray_over_pool": over,
        "identical_files": identical,
    }


def _verdict(speedup: float, over: float, share: float, identical: bool) -> str:
    """Each target, met or not; and, when Ray's fixed cost alone is more than the margin
    (``share`` of the pool's sweep), that Ray cannot be within it on this sweep."""
    line = (
        f"workers 2 / workers 1: {speedup:.2f}x "
        f"({'met' if speedup >= POOL_TARGET else 'NOT met'}: >= {POOL_TARGET}); "
        f"Ray vs workers 2: {over:+.0%} "
        f"({'met' if over <= RAY_TARGET else 'NOT met'}: within {RAY_TARGET:.0%}); "
        f"files identical: {identical}"
    )
    if share > RAY_TARGET:
        line += f"\nRay's fixed cost alone is {share:.0%} of this sweep on the pool."
    return line


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", help="the sweeps' seeds, START:STOP (default: per workload)")
    parser.add_argument("--workload", choices=[*WORKLOADS, "both"], default="both")
    args = parser.parse_args()
    console = Console()
    chosen = list(WORKLOADS) if args.workload == "both" else [args.workload]
    with console.status("timing Ray alone"):
        ray_s = ray_alone_s()
    results = {
        workload: measure(workload, args.seeds or SEEDS[workload], ray_s, console)
        for workload in chosen
    }
    path = write_results("sweep_scaling", results)
    console.print(f"Written to {path}.")
    return 0 if all(r["identical_files"] for r in results.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
