"""The two tables ``bench-camera`` prints (see :mod:`benchmarks.camera_path`)."""

from __future__ import annotations

import argparse
import math
import os
from typing import Any

from rich.table import Table

RATIO_TARGET = 1.10
"""Highest deploy / bare CPU ratio the camera path should cost."""
RATE_TOLERANCE = 0.05
"""Largest relative error of a received camera rate that still counts as sustained."""


def ratio_table(results: list[dict[str, Any]], args: argparse.Namespace) -> Table:
    """Per size: CPU per second of the bare loop and of deploy sim, and their ratio."""
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    table = Table(
        title=f"CPU s per wall s: deploy sim vs bare MuJoCo loop, cameras at "
        f"{args.camera_rate:g} Hz, {args.seconds:g} s windows",
        caption=f"{args.scene.name}; medians of {args.pairs} interleaved pairs (bare frames/s "
        f"rendered; ratio: median and range of the pairs' ratios); load average after: "
        f"{load} on {os.cpu_count()} cores",
    )
    columns = ("size", "bare loop", "deploy sim", "ratio", "target", "highest rate sustained")
    for column in columns:
        table.add_column(column, justify="left" if column == "size" else "right")
    for result in results:
        ratio = result["ratio"]
        colour = "green" if ratio <= RATIO_TARGET else "red"
        frames = [_frames_per_s(pair["bare"]["counts"]) for pair in result["pairs"]]
        best = result["highest_sustained_hz"]
        low, high = result["ratio_range"]
        table.add_row(
            result["size"],
            f"{result['bare_cpu_per_s']:.3f} ({min(frames):.1f}/s)",
            f"{result['deploy_cpu_per_s']:.3f}",
            f"[{colour}]{ratio:.2f}[/] ({low:.2f}-{high:.2f})",
            f"≤ {RATIO_TARGET:.2f}",
            "none" if best is None else f"{best:g} Hz",
        )
    return table


def _frames_per_s(counts: dict[str, float]) -> float:
    """Frames the bare loop rendered per second of its run (nan without counts)."""
    wall = counts.get("wall_s", 0.0)
    return counts.get("frames", 0.0) / wall if wall > 0 else math.nan


def rate_table(results: list[dict[str, Any]], args: argparse.Namespace) -> Table:
    """Per size and requested rate: the slowest camera's received rate and the verdict."""
    table = Table(
        title=f"deploy sim camera rate: received within {100 * RATE_TOLERANCE:g} % of "
        f"--camera-rate ({args.seconds:g} s each, tried in ascending order until one fails)"
    )
    columns = ("size", "requested", "slowest camera", "off", "deploy CPU/s", "sustained")
    for column in columns:
        table.add_column(column, justify="left" if column == "size" else "right")
    for result in results:
        for rate, trial in result["trials"].items():
            requested = float(rate)
            slowest = min(trial["received_hz"].values(), default=math.nan)
            off = (slowest - requested) / requested
            verdict = "[green]yes[/]" if trial["sustained"] else "[red]no[/]"
            table.add_row(
                result["size"],
                f"{requested:g} Hz",
                f"{slowest:.2f} Hz",
                f"{100 * off:+.1f} %",
                f"{trial['cpu_per_s']:.3f}",
                verdict,
            )
        table.add_section()
    return table
