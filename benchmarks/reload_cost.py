"""What loading a manifest and connecting a HAL cost the second time in one process.

A process remembers the documents it parsed (:mod:`openral_core.yaml_source`) and the
compiled models it read from the disk cache (:mod:`openral_mujoco.model_cache`). For each
robot this measures, in the same run, the median of ``--repeat`` calls with both memories
cleared before every call (the baseline: what every call cost before them) and with them
kept (what a sweep's resets or a test's examples pay), and prints the ratio. The disk
cache is warm in both: only the in-memory layers differ. Writes
``benchmarks/results/reload_cost.json``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

from openral_core import load_robot_by_id, yaml_source
from openral_core.paths import robots_dir
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_mujoco import model_cache
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results


def _forget() -> None:
    """Clear both in-process memories (the disk cache stays)."""
    yaml_source._PARSED.clear()
    model_cache._MEMORY.clear()


def _median_ms(call: Callable[[], object], repeat: int, cold: bool) -> float:
    """Median wall time of ``call`` [ms], the memories cleared before each call if ``cold``."""
    call()  # warm the disk cache and the imports
    times = []
    for _ in range(repeat):
        if cold:
            _forget()
        started = time.perf_counter()
        call()
        times.append((time.perf_counter() - started) * 1e3)
    return statistics.median(times)


def measure(robot_id: str, repeat: int) -> dict[str, float]:
    """Load and connect medians for ``robot_id``, without and with the memories [ms]."""
    hal = MujocoArmHAL.from_description(load_robot_by_id(robot_id))
    row: dict[str, float] = {}
    for name, call in (("load", lambda: load_robot_by_id(robot_id)), ("connect", hal.connect)):
        row[f"{name}_cold_ms"] = _median_ms(call, repeat, cold=True)
        row[f"{name}_kept_ms"] = _median_ms(call, repeat, cold=False)
        row[f"{name}_speedup"] = row[f"{name}_cold_ms"] / row[f"{name}_kept_ms"]
    hal.disconnect()
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=7, help="calls per median")
    parser.add_argument("robots", nargs="*", help="robot ids (default: every robot)")
    args = parser.parse_args()
    robots = args.robots or sorted(p.parent.name for p in robots_dir().glob("*/robot.yaml"))
    table = Table(title=f"Second load and connect in one process (median of {args.repeat})")
    columns = ("robot", "load cold ms", "load kept ms", "speed-up")
    for column in (*columns, "connect cold ms", "connect kept ms", "speed-up"):
        table.add_column(column, justify="left" if column == "robot" else "right")
    results = {}
    for robot_id in robots:
        row = results[robot_id] = measure(robot_id, args.repeat)
        kinds = ("cold_ms", "kept_ms", "speedup")
        cells = [f"{row[f'{name}_{kind}']:.1f}" for name in ("load", "connect") for kind in kinds]
        table.add_row(robot_id, *cells)
    Console(width=140).print(table)
    print(f"wrote {write_results('reload_cost', {'repeat': args.repeat, 'robots': results})}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
