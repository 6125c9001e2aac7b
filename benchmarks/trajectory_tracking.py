"""Joint-trajectory tracking on the franka tabletop: accuracy, and what following costs.

One :class:`~openral_bridge.trajectory_follower.TrajectoryFollower` feeds
``SimAttachedHAL.tick`` once per control period, as the deploy node's control loop does,
with panda_joint1 and panda_joint4 each moving +0.5 rad in 2.0 s. Three ways of handing the
samples to the HAL are compared:

- ``step``: each sample as an ordinary action (the set point slews to it and stops; no
  feed-forward), what a client streaming ``safe_action`` would get;
- ``glide linear`` / ``glide cubic``: what the control loop does with a trajectory
  (``tick(action, glide=True)``), without and with end velocities.

The error is ``/joint_states``' reading against the path at 0.5, 1.0, 1.5 and 2.0 s after
its start (the live test's instants). The cost is the time of a following tick over a
holding tick, both measured here in the same process (best of ``--repeats``). Run with
``just bench-trajectory``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np
from openral_bridge.joint_path import PathPoint, TrajectoryRequest
from openral_bridge.trajectory_follower import TrajectoryFollower, path_limits
from openral_core import open_robot_by_id
from openral_core.loader import load_scene
from openral_core.paths import repo_root
from openral_hal.sim_attached import SimAttachedHAL
from openral_sim.scene import build_scene
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results

JOINTS = ("panda_joint1", "panda_joint4")
INSTANTS_S = (0.5, 1.0, 1.5, 2.0)
MODES = ("step", "glide linear", "glide cubic")


def attached() -> SimAttachedHAL:
    """A connected SimAttachedHAL on the franka tabletop, cameras not rendered."""
    robot = open_robot_by_id("franka_panda")
    scene = load_scene(repo_root() / "robots" / "franka_panda" / "scenes" / "tabletop.yaml")
    hal = SimAttachedHAL(build_scene(scene, robot, render_observations=False), robot)
    hal.connect()
    return hal


def run(hal: SimAttachedHAL, mode: str) -> tuple[list[list[float]], float]:
    """(error per instant per joint [rad], seconds per following tick) of one trajectory."""
    hal.reset()
    follower = TrajectoryFollower(path_limits(hal.robot))
    slots = [hal.action_names.index(j) for j in JOINTS]
    state = hal.read_state()
    start = state.positions[slots]
    velocities = (0.0, 0.0) if mode == "glide cubic" else ()
    points = (
        PathPoint(0.0, tuple(start), velocities),
        PathPoint(2.0, tuple(start + 0.5), velocities),
    )
    hold = np.asarray(hal.hold_action())
    now = float(state.sim_time_s or 0.0)
    follower.submit(TrajectoryRequest(JOINTS, points), hold, now)
    begin, errors, spent, ticks = now, [], 0.0, 0
    while follower.active:
        step = follower.next_action(np.asarray(hal.hold_action()), now, hal.control_period_s)
        assert step is not None
        action, _ = step
        started = time.perf_counter()
        hal.tick(action, glide=mode != "step")
        spent, ticks = spent + time.perf_counter() - started, ticks + 1
        state = hal.read_state()
        now = float(state.sim_time_s or 0.0)
        if any(abs(now - begin - t) < 1e-6 for t in INSTANTS_S):
            s = (now - begin) / 2.0
            shape = 3 * s**2 - 2 * s**3 if mode == "glide cubic" else s
            errors.append(np.abs(state.positions[slots] - (start + 0.5 * shape)).tolist())
    return errors, spent / ticks


def hold_tick_s(hal: SimAttachedHAL, ticks: int) -> float:
    """Seconds per holding tick."""
    started = time.perf_counter()
    for _ in range(ticks):
        hal.tick(None)
    return (time.perf_counter() - started) / ticks


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3, help="runs per mode (best time)")
    args = parser.parse_args()
    console = Console()
    hal = attached()
    errors: dict[str, list[list[float]]] = {}
    cost = dict.fromkeys(MODES, np.inf)
    hold = np.inf
    try:
        for _ in range(args.repeats):
            hold = min(hold, hold_tick_s(hal, 40))
            for mode in MODES:
                errors[mode], seconds = run(hal, mode)
                cost[mode] = min(cost[mode], seconds)
    finally:
        hal.disconnect()
    table = Table(
        title="franka tabletop, panda_joint1 / panda_joint4 +0.5 rad in 2.0 s at 20 Hz: "
        "error against the path (rad) at",
    )
    for column in ("mode", *(f"{t:g} s" for t in INSTANTS_S), "tick / hold"):
        table.add_column(column, justify="left" if column == "mode" else "right")
    for mode in MODES:
        cells = [f"{a:.4f} / {b:.4f}" for a, b in errors[mode]]
        table.add_row(mode, *cells, f"{cost[mode] / hold:.2f}")
    console.print(table)
    path: Path = write_results(
        "trajectory_tracking",
        {
            "joints": list(JOINTS),
            "instants_s": list(INSTANTS_S),
            "errors_rad": errors,
            "tick_over_hold_tick": {mode: cost[mode] / hold for mode in MODES},
            "hold_tick_ms": hold * 1e3,
        },
    )
    console.print(f"Written to {path}.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
