"""``openral deploy sim`` from launch to live graph: first joint state, first sensor
messages, rates, CPU.

Each run launches ``openral deploy sim --no-viewer`` as a subprocess on a ROS domain of its
own and watches it from this process (:mod:`benchmarks.deploy_launch`): the time from
``Popen`` to the first ``/joint_states`` and to the first message of every sensor stream
(camera images, depth images and clouds, scans, odometry: :mod:`benchmarks.sensor_streams`),
then each stream's rate over a sustained window (arrival times at the subscriber) against
its nominal rate, and the deploy process's CPU use over the same window (``/proc``;
100 % = one core). ``--scene robots/panda_mobile/scenes/room.yaml`` measures the mobile
robot's depth, cloud, scan and odometry streams. One untimed launch
first fills the bytecode cache and the compiled-model cache (see
:mod:`benchmarks.deploy_launch` and :mod:`openral_mujoco.model_cache`); the timed runs then
start as a user's second launch of an unchanged scene does. ``--cold-runs`` more launches
each start with an empty model cache, as the first launch after changing the robot's model,
manifest or scene does; they are reported beside the target rows. Run with
``just bench-deploy``; the table (median and worst of the runs) is printed and written to
``benchmarks/results/deploy_startup.json``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from benchmarks.deploy_launch import (
    DEFAULT_SCENE,
    JOINT_STATES,
    REPO,
    deploy_env,
    received_rate,
    tree_cpu_seconds,
    warm_up,
    watched_deploy,
)
from benchmarks.results_file import write_results
from benchmarks.sensor_streams import Stream, sensor_streams

TARGETS = {"first_state_s": 1.0, "first_frames_s": 1.5, "rate_error": 0.05, "tf_cpu_points": 3.0}
"""Median launch → first /joint_states [s], median launch → first frame of every camera [s],
the largest relative rate error of a sensor stream over the window, and the deploy CPU that
publishing /tf and /tf_static adds (median with them less median without, % of one core)."""
ROOM_SCENE = REPO / "robots" / "panda_mobile" / "scenes" / "room.yaml"
"""The mobile manipulator's room: depth, cloud, scan and odometry streams."""
BOOT_TIMEOUT_S = 60.0
Run = dict[str, Any]
"""One launch's measures, as ``one_run`` returns them and the JSON stores them."""


def one_run(
    scene: Path,
    streams: list[Stream],
    window_s: float,
    rate_hz: float,
    model_cache: str = "",
    *,
    tf: bool = True,
) -> Run:
    """Launch, wait for every first message, measure a window, stop with SIGINT; with
    ``model_cache``, the launch's compiled-model cache is that folder; ``tf=False`` launches
    with ``--no-tf``."""
    env = {"OPENRAL_MODEL_CACHE": model_cache} if model_cache else None
    rate = ("--camera-rate", str(rate_hz)) if rate_hz else ()
    options = (*rate, *(() if tf else ("--no-tf",)))
    extra = {stream.topic: stream.kind for stream in streams}
    with watched_deploy(scene, [], *options, env=env, extra=extra) as (launch, watcher):
        booted = watcher.wait(lambda: all(watcher.arrivals.values()), BOOT_TIMEOUT_S)
        if not booted:
            raise RuntimeError(f"no first message on every topic within {BOOT_TIMEOUT_S} s")
        firsts = {topic: times[0] - launch.launched for topic, times in watcher.snapshot().items()}
        watcher.wait(lambda: bool(launch.active), 5.0)
        time.sleep(1.0)  # let discovery and start-up transients pass before the window
        watcher.reset()
        pid = launch.process.pid
        cpu0, wall0 = tree_cpu_seconds(pid), time.monotonic()
        time.sleep(window_s)
        cpu1, wall1 = tree_cpu_seconds(pid), time.monotonic()
        arrivals = watcher.snapshot()
    frames = {t: v for t, v in firsts.items() if t != JOINT_STATES}
    return {
        "active_s": launch.active[0] - launch.launched if launch.active else float("nan"),
        "first_state_s": firsts[JOINT_STATES],
        "first_frames_s": max(frames.values()),
        "first_frame_s": frames,
        "cpu_to_first_state_s": watcher.first_cpu_s[JOINT_STATES],
        "rates_hz": {topic: received_rate(times) for topic, times in arrivals.items()},
        "cpu_percent": 100.0 * (cpu1 - cpu0) / (wall1 - wall0),
        "exit_code": launch.exit_code,
    }


def parse_args() -> argparse.Namespace:
    """The command line: scene, number of runs, measuring window and camera rate."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument(
        "--scene",
        type=Path,
        action="append",
        help="deploy-scene file (repeatable; default: the franka tabletop, then the room)",
    )
    parser.add_argument("--runs", type=int, default=5, help="launches to time")
    parser.add_argument("--window", type=float, default=10.0, help="rate/CPU window [s]")
    parser.add_argument(
        "--camera-rate",
        type=float,
        default=10.0,
        help="deploy sim --camera-rate [Hz] (RGB, depth and lidar alike; 0: each sensor's own)",
    )
    parser.add_argument(
        "--cold-runs", type=int, default=3, help="launches with an empty model cache"
    )
    parser.add_argument(
        "--no-tf-runs",
        type=int,
        default=5,
        help="launches with --no-tf, each after a timed one (the CPU /tf costs)",
    )
    return parser.parse_args()


def time_runs(
    args: argparse.Namespace, streams: list[Stream], console: Console
) -> tuple[list[Run], list[Run], list[Run]]:
    """One untimed warm-up launch, ``args.runs`` measured ones (each of the first
    ``args.no_tf_runs`` followed by one with ``--no-tf``), then ``args.cold_runs`` each with
    an empty model cache, announcing each."""
    console.print(f"warm-up launch (not timed): {warm_up(args.scene):.1f} s")
    runs, no_tf, cold = [], [], []
    for index in range(args.runs):
        console.print(f"run {index + 1}/{args.runs} …")
        runs.append(one_run(args.scene, streams, args.window, args.camera_rate))
        if index < args.no_tf_runs:
            console.print(f"run {index + 1}/{args.runs} with --no-tf …")
            no_tf.append(one_run(args.scene, streams, args.window, args.camera_rate, tf=False))
    for index in range(args.cold_runs):
        console.print(f"run {index + 1}/{args.cold_runs} with an empty model cache …")
        with tempfile.TemporaryDirectory(prefix="openral-bench-cold-") as folder:
            cold.append(one_run(args.scene, streams, args.window, args.camera_rate, folder))
    return runs, cold, no_tf


def _target_row(table: Table, label: str, values: list[float], target: float, unit: str) -> None:
    """Median (green within ``target``, red over it), worst and the target."""
    median = statistics.median(values)
    colour = "green" if median < target else "red"
    table.add_row(
        label,
        f"[{colour}]{median:.2f} {unit}[/]",
        f"{max(values):.2f} {unit}",
        f"< {target:g} {unit}",
    )


def _startup_rows(table: Table, runs: list[Run], cold: list[Run], streams: list[Stream]) -> None:
    """Launch to the first joint state and to every sensor stream's first message (also
    with an empty model cache), to each stream's, and to the printed ``running`` line."""
    labels = {"first_state_s": "/joint_states", "first_frames_s": "message of every sensor"}
    for key, label in labels.items():
        _target_row(table, f"launch → first {label}", [r[key] for r in runs], TARGETS[key], "s")
        if cold:
            values = [r[key] for r in cold]
            row = (f"{statistics.median(values):.2f} s", f"{max(values):.2f} s", "")
            table.add_row(f"  with an empty model cache ({len(cold)} runs)", *row)
    for stream in streams:
        firsts = [r["first_frame_s"][stream.topic] for r in runs]
        row = (f"{statistics.median(firsts):.2f} s", f"{max(firsts):.2f} s", "")
        table.add_row(f"  first {stream.topic}", *row)
    cpu = [r["cpu_to_first_state_s"] for r in runs]
    row = (f"{statistics.median(cpu):.2f} s", f"{max(cpu):.2f} s", "")
    table.add_row("deploy CPU until its first /joint_states", *row)
    actives = [r["active_s"] for r in runs]
    row = (f"{statistics.median(actives):.2f} s", f"{max(actives):.2f} s", "")
    table.add_row("launch → `running` printed", *row)


def _streaming_rows(
    table: Table, runs: list[Run], streams: list[Stream], args: argparse.Namespace
) -> None:
    """Each stream's rate error over the window, the joint-state rate and the deploy CPU."""
    for stream in streams:
        rates = [r["rates_hz"][stream.topic] for r in runs]
        worst = max(abs(x - stream.rate_hz) / stream.rate_hz for x in rates)
        table.add_row(
            f"{stream.topic} ({stream.rate_hz:g} Hz) over {args.window:g} s",
            f"{statistics.median(rates):.2f} Hz",
            f"[{'green' if worst <= TARGETS['rate_error'] else 'red'}]{100 * worst:.1f} % off[/]",
            f"± {100 * TARGETS['rate_error']:g} %",
        )
    states_hz = [r["rates_hz"][JOINT_STATES] for r in runs]
    table.add_row("/joint_states rate", f"{statistics.median(states_hz):.1f} Hz", "", "")
    cpu = [r["cpu_percent"] for r in runs]
    table.add_row("deploy process CPU", f"{statistics.median(cpu):.0f} %", f"{max(cpu):.0f} %", "")


def _tf_rows(table: Table, runs: list[Run], no_tf: list[Run]) -> None:
    """The deploy CPU without /tf and what /tf adds (medians, in points of one core)."""
    if not no_tf:
        return
    without = [r["cpu_percent"] for r in no_tf]
    table.add_row(
        f"deploy process CPU with --no-tf ({len(no_tf)} runs)",
        f"{statistics.median(without):.1f} %",
        f"{max(without):.1f} %",
        "",
    )
    added = tf_cpu_points(runs, no_tf)
    colour = "green" if added <= TARGETS["tf_cpu_points"] else "red"
    table.add_row(
        "  CPU added by /tf and /tf_static",
        f"[{colour}]{added:+.1f} points[/]",
        "",
        f"≤ {TARGETS['tf_cpu_points']:g} points",
    )


def tf_cpu_points(runs: list[Run], no_tf: list[Run]) -> float:
    """Median deploy CPU with /tf less the median without [% of one core]."""
    with_tf = statistics.median(r["cpu_percent"] for r in runs)
    return with_tf - statistics.median(r["cpu_percent"] for r in no_tf)


def results_table(
    args: argparse.Namespace,
    streams: list[Stream],
    runs: tuple[list[Run], list[Run], list[Run]],
    load: tuple[float, ...],
) -> Table:
    """The printed summary: start-up rows, then streaming rows, median and worst of the runs."""
    table = Table(
        title=f"deploy sim start-up and streaming: {args.scene.name}, median of {args.runs} runs",
        caption=f"load average before: {', '.join(f'{x:.2f}' for x in load)} on "
        f"{os.cpu_count()} cores; bytecode: {bytecode_note()}",
    )
    for column in ("measure", "median", "worst", "target"):
        table.add_column(column, justify="left" if column == "measure" else "right")
    _startup_rows(table, runs[0], runs[1], streams)
    _streaming_rows(table, runs[0], streams, args)
    _tf_rows(table, runs[0], runs[2])
    return table


def bytecode_note() -> str:
    """Where the launched commands keep their bytecode."""
    prefix = deploy_env().get("PYTHONPYCACHEPREFIX")
    return f"cached in {prefix}" if prefix else "the usual __pycache__ folders"


def save_results(
    args: argparse.Namespace, runs: tuple[list[Run], list[Run], list[Run]], load: tuple[float, ...]
) -> Path:
    """Write the settings, targets and every run to ``benchmarks/results/deploy_startup.json``
    (``deploy_startup_<scene>.json`` for another scene than the default)."""
    scene = args.scene.relative_to(REPO) if args.scene.is_relative_to(REPO) else args.scene
    suffix = (
        "" if args.scene == DEFAULT_SCENE else f"_{args.scene.parent.parent.name}_{args.scene.stem}"
    )
    return write_results(
        "deploy_startup" + suffix,
        {
            "scene": str(scene),
            "camera_rate_hz": args.camera_rate,
            "window_s": args.window,
            "cpu_count": os.cpu_count(),
            "load_average_before": load,
            "bytecode": bytecode_note(),
            "targets": TARGETS,
            "medians": _medians(runs[0]),
            "cold_medians": _medians(runs[1]) if runs[1] else None,
            "runs": runs[0],
            "cold_runs": runs[1],
            "no_tf_runs": runs[2],
            "tf_cpu_points": tf_cpu_points(runs[0], runs[2]) if runs[2] else None,
        },
    )


def _medians(runs: list[Run]) -> dict[str, float]:
    keys = ("first_state_s", "first_frames_s", "cpu_to_first_state_s", "active_s")
    return {key: statistics.median(r[key] for r in runs) for key in keys}


def main() -> int:
    """Time the runs of each scene, print its table, write its JSON; 1 if any run did not
    exit cleanly."""
    args = parse_args()
    console = Console()
    clean = True
    for scene in args.scene or [DEFAULT_SCENE, ROOM_SCENE]:
        args.scene = scene
        streams = sensor_streams(scene, args.camera_rate or None)
        load = os.getloadavg()
        runs = time_runs(args, streams, console)
        console.print(results_table(args, streams, runs, load))
        path = save_results(args, runs, load)
        console.print(
            "Times from Popen (includes interpreter start-up); rates from arrival times at a "
            f"subscriber in this process; CPU: 100 % = one core. Written to {path}."
        )
        clean &= all(r["exit_code"] == 0 for r in runs[0] + runs[1] + runs[2])
    return 0 if clean else 1


if __name__ == "__main__":
    raise SystemExit(main())
