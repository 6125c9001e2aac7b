"""Sweep scaling on this machine: one process, a pool of two, and Ray with two CPUs.

Each workload runs as ``openral sim sweep`` four ways (``--workers 1``, ``--workers 2``,
``--workers 2 --ray``, and ``--ray ADDRESS`` joining a Ray instance of 2 CPUs started
beforehand) on the franka tabletop without videos. Two times are compared, both the
sweep's own (``summary.json``):

- ``run_wall_s``, end to end: from the first episode handed out to the last result
  written, so the pool's forks and Ray's start-up count; the command's imports and scene
  build (the same for every run) and the workers' shutdown do not;
- ``episodes_wall_s``, the episodes alone: from the moment every worker is up with the
  scenes built (``startup_s`` after the start) to the last result written.

Workloads:

- ``cameras``: ``wave`` observing its two camera slots, 200 steps, seeds 0:40 (each 10 Hz
  camera rendered at 10 Hz on the 20 Hz control loop: 202 frames an episode, about half the 400
  rendered before frames followed the sensor schedule; the table's title counts them);
- ``lift``: ``scripted_lift`` over seeds 0:20 (the issue's sweep; ~60 steps,
  about a second on two cores; ~60-90 ms an episode).

The same run also times Ray's fixed cost alone: a Ray session that starts, runs one empty
task per CPU and ends, as ``openral sim sweep --ray`` starts it. A sweep shorter than a
few times that cannot be within 15 % on Ray, whatever the episodes.

Targets: ``--workers 2`` ≥ 1.7 x ``--workers 1`` on 2 cores, end to end; Ray within 15 %
of ``--workers 2`` on the episodes, and end to end on a sweep that runs minutes
(``cameras``). The four ``episodes.jsonl`` of a workload must be identical but for wall
times. Run with ``just bench-sweep`` (``--workload lift`` for the quick one).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from contextlib import nullcontext
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

from openral_core.paths import repo_root
from rich.console import Console
from rich.table import Table

from benchmarks.ray_head import ray_head
from benchmarks.results_file import write_results

SCENE = "robots/franka_panda/scenes/tabletop.yaml"
WORKLOADS = {
    "cameras": ("--policy", "wave", "--steps", "200"),
    "lift": ("--policy", "scripted_lift"),
}
SEEDS = {"cameras": "0:40", "lift": "0:20"}
REPEATS = {"cameras": 1, "lift": 5}
"""Sweeps per run: the times compared are the medians (a lift sweep lasts about a second)."""
RAY_ALONE = """
import time
from openral_eval.ray_session import ray_session
started = time.perf_counter()
with ray_session("local", 2) as ray:
    ray.get([ray.remote(num_cpus=1)(lambda: 0).remote() for _ in range(2)])
    print(time.perf_counter() - started)
"""
RUNS = {
    "workers 1": ("--workers", "1"),
    "workers 2": ("--workers", "2"),
    "ray": ("--workers", "2", "--ray"),
    "ray joined": ("--ray", "ADDRESS"),
}
"""``ray joined``: a Ray instance of 2 CPUs already running on this machine (started before
the sweep, its start not counted), joined by its address, as a cluster would be."""
POOL_TARGET, RAY_TARGET = 1.7, 0.15


Times = dict[str, float]
"""A sweep's ``run_wall_s``, ``startup_s`` and ``episodes_wall_s`` [s]."""


def timed(workload: str, run: str, seeds: str, out: Path) -> tuple[Times, list[dict[str, object]]]:
    """The sweep's times and its lines without wall times."""
    folder = out / workload / run.replace(" ", "_")
    command = [str(Path(sys.executable).parent / "openral"), "sim", "sweep", "--config", SCENE]
    command += ["--seeds", seeds, "--video", "none", "--out", str(folder)]
    command += [*WORKLOADS[workload], *RUNS[run]]
    with ray_head(2) if "ADDRESS" in command else nullcontext() as head:
        if head is not None:
            command[command.index("ADDRESS")] = head.address
        done = subprocess.run(command, capture_output=True, text=True, cwd=repo_root(), check=False)
    if done.returncode != 0:
        raise SystemExit(f"{workload} / {run} failed:\n{done.stderr}")
    summary = json.loads((folder / "summary.json").read_text())
    seconds = {key: float(summary[key]) for key in ("run_wall_s", "startup_s", "episodes_wall_s")}
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
    """Run one workload three ways (each :data:`REPEATS` times, runs interleaved); print its
    table; its results (median times)."""
    every: dict[str, list[Times]] = {run: [] for run in RUNS}
    files: dict[str, list[dict[str, object]]] = {}
    with tempfile.TemporaryDirectory() as folder, console.status("sweeping") as status:
        for repeat in range(REPEATS[workload]):
            for run in RUNS:
                status.update(f"{workload}: {run} ({repeat + 1} of {REPEATS[workload]})")
                shutil.rmtree(Path(folder) / workload, ignore_errors=True)
                own, lines = timed(workload, run, seeds, Path(folder))
                every[run].append(own)
                if files.setdefault(run, lines) != lines:
                    raise SystemExit(f"{workload} / {run}: a repeat wrote a different file")
    times = {
        run: {k: statistics.median(t[k] for t in runs) for k in runs[0]}
        for run, runs in every.items()
    }
    episodes = len(files["workers 1"])
    frames = statistics.mean(float(str(line.get("frames", 0))) for line in files["workers 1"])
    console.print(_table(workload, seeds, episodes, times, ray_s, frames))
    speedup = times["workers 1"]["run_wall_s"] / times["workers 2"]["run_wall_s"]
    over = {
        f"{ray}, {name}": times[ray][key] / times["workers 2"][key] - 1.0
        for ray in ("ray", "ray joined")
        for key, name in PHASES.items()
    }
    identical = all(lines == files["workers 1"] for lines in files.values())
    console.print(_verdict(speedup, over, ray_s / times["workers 2"]["run_wall_s"], identical))
    return {
        "seeds": seeds,
        "episodes": episodes,
        "frames_per_episode": frames,
        "repeats": REPEATS[workload],
        "times_s": times,
        "ray_alone_s": ray_s,
        "pool_speedup": speedup,
        "ray_over_pool": over,
        "identical_files": identical,
    }


PHASES = {"run_wall_s": "end to end", "episodes_wall_s": "episodes"}


def _table(
    workload: str,
    seeds: str,
    episodes: int,
    times: dict[str, Times],
    ray_s: float,
    frames: float,
) -> Table:
    """One row per run: its start-up, episodes and end-to-end seconds, and the ratios."""
    table = Table(
        title=f"{workload}: {' '.join(WORKLOADS[workload])}, seeds {seeds} ({episodes} "
        f"episodes, {frames:.0f} camera frames each), {os.cpu_count()} cores, median of "
        f"{REPEATS[workload]}"
    )
    columns = ("run", "start-up s", "episodes s", "end to end s", "vs workers 1 (end to end)")
    for column in (*columns, "vs workers 2 (episodes)", "vs workers 2 (end to end)"):
        table.add_column(column, justify="left" if column == "run" else "right")
    base, pool = times["workers 1"], times["workers 2"]
    for run, own in times.items():
        table.add_row(
            run,
            f"{own['startup_s']:.2f}",
            f"{own['episodes_wall_s']:.2f}",
            f"{own['run_wall_s']:.2f}",
            f"{base['run_wall_s'] / own['run_wall_s']:.2f}x",
            f"{own['episodes_wall_s'] / pool['episodes_wall_s'] - 1.0:+.0%}",
            f"{own['run_wall_s'] / pool['run_wall_s'] - 1.0:+.0%}",
        )
    table.add_row("Ray alone (no episode)", f"{ray_s:.2f}", "", "", "", "", "")
    return table


def _verdict(speedup: float, over: dict[str, float], share: float, identical: bool) -> str:
    """Each target, met or not; and, when Ray's fixed cost alone is more than the margin
    (``share`` of the pool's sweep, end to end), that Ray cannot be within it end to end."""
    met = {True: "met", False: "NOT met"}
    line = (
        f"workers 2 / workers 1: {speedup:.2f}x ({met[speedup >= POOL_TARGET]}: >= "
        f"{POOL_TARGET}); files identical: {identical}"
    )
    for what, ratio in over.items():
        line += (
            f"\n{what} vs workers 2: {ratio:+.0%} "
            f"({met[ratio <= RAY_TARGET]}: within {RAY_TARGET:.0%})"
        )
    if share > RAY_TARGET:
        line += (
            f"\nRay's start-up alone is {share:.0%} of this sweep on the pool: end to end, "
            "a new Ray instance cannot be within the margin on it, whatever its episodes."
        )
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
