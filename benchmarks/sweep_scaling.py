"""Sweep scaling on this machine: one process, a pool of two, and Ray with two CPUs.

The same sweep (the franka tabletop, ``--seeds``, ``--policy``, no videos) runs three times
as ``openral sim sweep`` would run it, timed from the command's start to its last line
(so Ray's start-up and the pool's process spawns count). It reports wall time, episodes
per second and the speed-ups; the targets are ``--workers 2`` ≥ 1.7 x ``--workers 1`` on
2 cores and Ray within 15 % of ``--workers 2``. The three ``episodes.jsonl`` must be
identical but for wall times. Run with ``just bench-sweep``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

from openral_core.paths import repo_root
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results

SCENE = "robots/franka_panda/scenes/tabletop.yaml"
RUNS = {
    "workers 1": ("--workers", "1"),
    "workers 2": ("--workers", "2"),
    "ray": ("--workers", "2", "--ray"),
}
POOL_TARGET, RAY_TARGET = 1.7, 0.15


def timed(
    name: str, args: tuple[str, ...], seeds: str, policy: str, out: Path
) -> tuple[float, list[dict[str, object]]]:
    """Wall seconds of one sweep and its lines without wall times."""
    command = [str(Path(sys.executable).parent / "openral"), "sim", "sweep", "--config", SCENE]
    command += [
        "--seeds",
        seeds,
        "--policy",
        policy,
        "--video",
        "none",
        "--out",
        str(out / name),
        *args,
    ]
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, cwd=repo_root(), check=False)
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"{name} failed:\n{done.stderr}")
    lines = [json.loads(line) for line in (out / name / "episodes.jsonl").read_text().splitlines()]
    return seconds, [{k: v for k, v in line.items() if k != "wall_time_s"} for line in lines]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", default="0:20", help="the sweep's seeds (START:STOP)")
    parser.add_argument("--policy", default="scripted_lift", help="the policy swept")
    args = parser.parse_args()
    console = Console()
    seconds: dict[str, float] = {}
    files: dict[str, list[dict[str, object]]] = {}
    with tempfile.TemporaryDirectory() as folder, console.status("sweeping") as status:
        for name, extra in RUNS.items():
            status.update(f"{name}: {args.policy} over seeds {args.seeds}")
            seconds[name], files[name] = timed(name, extra, args.seeds, args.policy, Path(folder))
    identical = files["workers 1"] == files["workers 2"] == files["ray"]
    episodes = len(files["workers 1"])
    pool = seconds["workers 1"] / seconds["workers 2"]
    ray = seconds["ray"] / seconds["workers 2"] - 1.0
    table = Table(title=f"{args.policy} on {SCENE}, {episodes} episodes, {os.cpu_count()} cores")
    for column in ("run", "wall s", "episodes/s", "vs workers 1", "vs workers 2"):
        table.add_column(column, justify="left" if column == "run" else "right")
    for name in RUNS:
        table.add_row(
            name,
            f"{seconds[name]:.1f}",
            f"{episodes / seconds[name]:.2f}",
            f"{seconds['workers 1'] / seconds[name]:.2f}x",
            f"{seconds[name] / seconds['workers 2'] - 1.0:+.0%}",
        )
    console.print(table)
    path = write_results(
        "sweep_scaling",
        {
            "policy": args.policy,
            "seeds": args.seeds,
            "episodes": episodes,
            "wall_s": seconds,
            "pool_speedup": pool,
            "ray_over_pool": ray,
            "identical_files": identical,
        },
    )
    console.print(
        f"workers 2 / workers 1: {pool:.2f}x (target ≥ {POOL_TARGET}); Ray vs workers 2: "
        f"{ray:+.0%} (target within {RAY_TARGET:.0%}); files identical: {identical}. "
        f"Written to {path}."
    )
    return 0 if identical else 1


if __name__ == "__main__":
    raise SystemExit(main())
