"""The camera path of ``openral deploy sim``: CPU against a bare MuJoCo loop, and top rate.

For each image size (the scene file's ``observation`` replaced, in a temporary copy):

1. CPU per wall second (user + system, every thread, the process and its descendants, from
   ``/proc``) of the bare loop of :mod:`benchmarks.camera_bare` (same composed scene, same
   control rate, same cameras at the same rate, rendered with ``mujoco.Renderer``, no ROS),
   and of ``deploy sim --camera-rate R`` with a subscriber on every image topic, each over
   the same window once it is up, in ``--pairs`` interleaved pairs (bare, then deploy; other
   work on a shared machine comes and goes, and one 6 s window of either moves by up to
   ~10 %); the median of the pairs' ratios deploy / bare is the camera path's overhead, and
   their range is shown beside it. Each run's CPU is also split by thread
   (:mod:`benchmarks.camera_threads`).
2. The highest camera rate ``deploy sim`` sustains: ``--camera-rate`` 5, 10, 20, 30, 60 Hz
   in turn (until one fails), each sustained when every camera's rate received by the
   subscriber (arrival times, :mod:`benchmarks.deploy_launch`) is within 5 % of it.

Run with ``just bench-camera``; the tables are printed and written to
``benchmarks/results/camera_path.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from openral_core.loader import load_scene
from openral_core.models import RgbSensor
from openral_sim.scene import scene_robot
from rich.console import Console
from rich.table import Table

from benchmarks.camera_report import RATE_TOLERANCE, rate_table, ratio_table
from benchmarks.camera_threads import cpu_window, thread_table
from benchmarks.deploy_launch import (
    DEFAULT_SCENE,
    REPO,
    Launch,
    camera_topic,
    deploy_env,
    received_rate,
    warm_up,
    watched_deploy,
)
from benchmarks.results_file import write_results

UP_TIMEOUT_S = 60.0
SETTLE_S = 1.0
"""Pause between a process being up and its measured window [s]."""
Size = tuple[int, int]
"""(width, height) [px]."""


def sustained(requested_hz: float, received_hz: Mapping[str, float]) -> bool:
    """Every camera received within :data:`RATE_TOLERANCE` of ``requested_hz`` (a camera that
    delivered under two frames, nan, is not)."""
    return bool(received_hz) and all(
        abs(rate - requested_hz) <= RATE_TOLERANCE * requested_hz for rate in received_hz.values()
    )


def highest_sustained(trials: Mapping[float, Mapping[str, float]]) -> float | None:
    """The highest requested rate [Hz] that was sustained with every lower one tried also
    sustained (``trials``: requested rate → received rate by camera); None if the lowest
    failed."""
    best = None
    for requested in sorted(trials):
        if not sustained(requested, trials[requested]):
            break
        best = requested
    return best


def parse_size(text: str) -> Size:
    """``"640x480"`` → (640, 480)."""
    width, _, height = text.lower().partition("x")
    return int(width), int(height)


def sized_scene(scene: Path, size: Size, folder: Path) -> Path:
    """A copy of ``scene`` whose images are ``size`` and whose cameras are its RGB sensors
    only (a depth camera is not part of the camera path; bench-deploy has its rows),
    written into ``folder`` (JSON, which is YAML) after it validated."""
    loaded = load_scene(scene)
    rgb = {s.name for s in scene_robot(loaded).description.sensors if isinstance(s, RgbSensor)}
    document = loaded.model_dump(mode="json", exclude_none=True)
    document["scene"]["cameras"] = [c for c in document["scene"]["cameras"] if c in rgb]
    document["scene"]["observation"]["width"], document["scene"]["observation"]["height"] = size
    path = folder / f"{scene.stem}_{size[0]}x{size[1]}.yaml"
    path.write_text(json.dumps(document, indent=2) + "\n")
    load_scene(path)  # refuse a copy the loader would refuse, here rather than in a child
    return path


def measure_bare(scene: Path, rate_hz: float, window_s: float) -> dict[str, Any]:
    """CPU per second of the bare loop over ``window_s``, and what the loop counted."""
    command = [sys.executable, "-m", "benchmarks.camera_bare", "--scene", str(scene)]
    command += ["--camera-rate", str(rate_hz)]
    process = subprocess.Popen(
        command, cwd=REPO, env=deploy_env(), stdout=subprocess.PIPE, text=True
    )
    launch = Launch(process, time.monotonic(), marker="ready")
    try:
        if not launch.wait_active(UP_TIMEOUT_S):
            raise RuntimeError(f"the bare loop did not start: {launch.lines[-5:]}")
        time.sleep(SETTLE_S)
        cpu, threads = cpu_window(process.pid, window_s)
    finally:
        launch.stop()
    counts = json.loads(launch.lines[-1]) if launch.lines else {}
    return {"cpu_per_s": cpu, "threads": threads, "counts": counts, "exit_code": launch.exit_code}


def measure_deploy(
    scene: Path, cameras: list[str], rate_hz: float, window_s: float
) -> dict[str, Any]:
    """``deploy sim --camera-rate rate_hz`` once up: CPU per second and each camera's received
    rate over ``window_s``."""
    options = ("--camera-rate", str(rate_hz))
    with watched_deploy(scene, cameras, *options) as (launch, watcher):
        if not watcher.wait(lambda: all(watcher.arrivals.values()), UP_TIMEOUT_S):
            raise RuntimeError(f"deploy sim sent no message on some topic in {UP_TIMEOUT_S} s")
        launch.wait_active(5.0)
        time.sleep(SETTLE_S)
        watcher.reset()
        cpu, threads = cpu_window(launch.process.pid, window_s)
        arrivals = watcher.snapshot()
    received = {camera: received_rate(arrivals[camera_topic(camera)]) for camera in cameras}
    return {
        "cpu_per_s": cpu,
        "threads": threads,
        "received_hz": received,
        "sustained": sustained(rate_hz, received),
        "exit_code": launch.exit_code,
    }


def measure_pairs(
    scene: Path, cameras: list[str], args: argparse.Namespace, console: Console, label: str
) -> list[dict[str, Any]]:
    """``args.pairs`` interleaved runs of the bare loop and of deploy sim at
    ``args.camera_rate``, each pair with its ratio (deploy / bare CPU per second)."""
    pairs = []
    for index in range(args.pairs):
        console.print(
            f"{label}: pair {index + 1}/{args.pairs} at {args.camera_rate:g} Hz: "
            "bare MuJoCo loop, then deploy sim …"
        )
        bare = measure_bare(scene, args.camera_rate, args.seconds)
        deploy = measure_deploy(scene, cameras, args.camera_rate, args.seconds)
        ratio = deploy["cpu_per_s"] / bare["cpu_per_s"] if bare["cpu_per_s"] > 0 else math.inf
        pairs.append({"bare": bare, "deploy": deploy, "ratio": ratio})
    return pairs


def measure_size(
    scene: Path, size: Size, args: argparse.Namespace, console: Console
) -> dict[str, Any]:
    """The interleaved pairs and the rate search (which reuses the first pair's deploy run
    at ``args.camera_rate``) at ``size``."""
    cameras = list(load_scene(scene).scene.cameras)
    label = f"{size[0]}x{size[1]}"
    pairs = measure_pairs(scene, cameras, args, console, label)
    trials: dict[float, dict[str, Any]] = {args.camera_rate: pairs[0]["deploy"]}
    for rate in sorted(set(args.rates)):
        if rate not in trials:
            console.print(f"{label}: deploy sim --camera-rate {rate:g} …")
            trials[rate] = measure_deploy(scene, cameras, rate, args.seconds)
        if not trials[rate]["sustained"]:
            break
    tried = {rate: trial["received_hz"] for rate, trial in trials.items() if rate in args.rates}
    ratios = [pair["ratio"] for pair in pairs]
    return {
        "size": label,
        "bare_cpu_per_s": statistics.median(pair["bare"]["cpu_per_s"] for pair in pairs),
        "deploy_cpu_per_s": statistics.median(pair["deploy"]["cpu_per_s"] for pair in pairs),
        "ratio": statistics.median(ratios),
        "ratio_range": [min(ratios), max(ratios)],
        "pairs": pairs,
        "median_pair": sorted(range(len(pairs)), key=lambda i: ratios[i])[len(pairs) // 2],
        "trials": {f"{rate:g}": trial for rate, trial in sorted(trials.items())},
        "highest_sustained_hz": highest_sustained(tried),
    }


def parse_args() -> argparse.Namespace:
    """Scene, window, sizes, the camera rate of the CPU comparison and the rates to try."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scene", type=Path, default=DEFAULT_SCENE, help="deploy-scene file")
    parser.add_argument(
        "--seconds", type=float, default=6.0, help="measured window of every run [s]"
    )
    parser.add_argument(
        "--sizes", default="128x128,640x480", help="image sizes WxH, comma-separated [px]"
    )
    parser.add_argument(
        "--camera-rate", type=float, default=10.0, help="camera rate of the CPU ratio [Hz]"
    )
    parser.add_argument(
        "--pairs", type=int, default=3, help="interleaved bare/deploy runs of the CPU ratio"
    )
    parser.add_argument(
        "--rates", default="5,10,20,30,60", help="camera rates to try, comma-separated [Hz]"
    )
    args = parser.parse_args()
    args.sizes = [parse_size(text) for text in args.sizes.split(",")]
    args.rates = sorted({float(text) for text in args.rates.split(",")})
    return args


def main() -> int:
    """Measure every size, print the two tables, write the JSON; 1 if a run did not exit 0."""
    args = parse_args()
    console = Console()
    load = os.getloadavg()
    started = time.monotonic()
    console.print(f"warm-up launch (not timed): {warm_up(args.scene):.1f} s")
    with tempfile.TemporaryDirectory(prefix="bench-camera-") as folder:
        results = [
            measure_size(sized_scene(args.scene, size, Path(folder)), size, args, console)
            for size in args.sizes
        ]
    tables: list[Table] = [
        ratio_table(results, args),
        rate_table(results, args),
        thread_table(
            [
                (f"{result['size']} {side}", pair[side]["threads"])
                for result in results
                for pair in [result["pairs"][result["median_pair"]]]
                for side in ("bare", "deploy")
            ],
            f"CPU s per wall s by thread, cameras at {args.camera_rate:g} Hz (median pair)",
        ),
    ]
    for table in tables:
        console.print(table)
    scene = args.scene.relative_to(REPO) if args.scene.is_relative_to(REPO) else args.scene
    path = write_results(
        "camera_path",
        {
            "scene": str(scene),
            "seconds": args.seconds,
            "camera_rate_hz": args.camera_rate,
            "rates_hz": args.rates,
            "rate_tolerance": RATE_TOLERANCE,
            "cpu_count": os.cpu_count(),
            "load_average_before": load,
            "results": results,
        },
    )
    console.print(
        f"CPU: user + system seconds per wall second (1.0 = one core), from /proc; rates from "
        f"arrival times at a subscriber in this process. {time.monotonic() - started:.0f} s. "
        f"Written to {path}."
    )
    runs = [pair[side] for r in results for pair in r["pairs"] for side in ("bare", "deploy")]
    codes = [run["exit_code"] for run in runs]
    codes += [t["exit_code"] for r in results for t in r["trials"].values()]
    return 0 if all(code == 0 for code in codes) else 1


if __name__ == "__main__":
    raise SystemExit(main())
