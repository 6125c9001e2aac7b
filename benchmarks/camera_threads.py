"""CPU per thread of a process tree, from ``/proc``, grouped by what the thread does.

``bench-camera`` reports where ``deploy sim``'s CPU goes: its main thread (the rclpy
executor), ``openral-pacer`` (control tick, ``/clock``, ``/joint_states``, frame requests),
``openral-render`` (the cameras), Mesa's ``llvmpipe-N`` threads (grouped as ``llvmpipe``)
and FastDDS's ``dds.*`` threads (grouped as ``dds``); the bare loop's main thread steps
and renders. The openral threads name themselves in the kernel
(:mod:`openral_bridge.os_thread`); a thread that did not is listed under ``other``.
"""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path

from rich.table import Table

from benchmarks.deploy_launch import CLOCK_TICKS, descendants, tree_cpu_seconds

GROUPS = ("main", "openral-pacer", "openral-render", "llvmpipe", "dds", "other")
"""Thread groups in the order the table shows them."""
NAMED = ("openral-pacer", "openral-render")
"""Threads that name themselves (:mod:`openral_bridge.os_thread`)."""


def thread_group(comm: str, is_main: bool, program: str) -> str:
    """The group of one thread from its kernel name (``comm``)."""
    if is_main:
        return "main"
    if comm.startswith("llvmpipe"):
        return "llvmpipe"
    if comm.startswith("dds."):
        return "dds"
    return comm if comm in NAMED and comm != program else "other"


def thread_ticks(pid: int) -> Counter[str]:
    """utime + stime so far of every live thread of ``pid`` and its descendants, summed
    per group [clock ticks]."""
    ticks: Counter[str] = Counter()
    for process in descendants(pid):
        try:
            program = Path(f"/proc/{process}/comm").read_text().strip()
            tasks = list(Path(f"/proc/{process}/task").iterdir())
        except OSError:  # ended while we looked
            continue
        for task in tasks:
            try:
                stat = (task / "stat").read_text()
            except OSError:
                continue
            comm = stat[stat.index("(") + 1 : stat.rindex(")")]
            fields = stat.rsplit(")", 1)[1].split()
            group = thread_group(comm, int(task.name) == process, program)
            ticks[group] += int(fields[11]) + int(fields[12])
    return ticks


def cpu_window(pid: int, window_s: float) -> tuple[float, dict[str, float]]:
    """CPU seconds per wall second over ``window_s`` of ``pid`` and its descendants: in all
    (as :func:`~benchmarks.deploy_launch.tree_cpu_seconds` counts it) and per thread group
    (threads that ended within the window are missing from the groups)."""
    cpu0, threads0, wall0 = tree_cpu_seconds(pid), thread_ticks(pid), time.monotonic()
    time.sleep(window_s)
    cpu1, threads1 = tree_cpu_seconds(pid), thread_ticks(pid)
    wall = time.monotonic() - wall0
    groups = {
        group: (threads1[group] - threads0[group]) / CLOCK_TICKS / wall
        for group in GROUPS
        if group in threads1
    }
    return (cpu1 - cpu0) / wall, groups


def thread_table(rows: list[tuple[str, dict[str, float]]], title: str) -> Table:
    """One row per (label, CPU per second by group) [cores]."""
    table = Table(title=title)
    table.add_column("run")
    for group in GROUPS:
        table.add_column(group, justify="right")
    for label, groups in rows:
        table.add_row(label, *(f"{groups[g]:.3f}" if g in groups else "-" for g in GROUPS))
    return table
