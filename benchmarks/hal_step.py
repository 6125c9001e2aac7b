"""HAL overhead per robot: send_action + step + read_state against a raw mj_step loop.

Both loops run on the same model in the same process, one after the other, so the ratio
cancels out the machine's speed. Run with ``just bench-hal``; the table is printed and written
to ``benchmarks/results/hal_step.json``.
"""

from __future__ import annotations

import argparse
import time

import mujoco
from openral_core import load_robot_by_id, robot_ids
from openral_hal.mujoco_arm import MujocoArmHAL
from rich.console import Console
from rich.progress import track
from rich.table import Table

from benchmarks.results_file import write_results

TARGET_AT_ONE = {"franka_panda": 1.5}
"""Raw-over-HAL ratio with one physics step per action each robot should stay under."""
TARGET_AT_CONTROL = {"franka_panda": 1.10}
"""The same at a control rate; every other robot: :data:`DEFAULT_TARGET_AT_CONTROL`."""
DEFAULT_TARGET_AT_CONTROL = 1.2


def raw_rate(model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> float:
    """mj_step calls per second."""
    start = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return steps / (time.perf_counter() - start)


def hal_rate(hal: MujocoArmHAL, steps: int, substeps: int) -> float:
    """Physics steps per second of the HAL loop: send_action, ``substeps`` physics steps,
    read_state."""
    action = hal.read_state().positions.copy()
    start = time.perf_counter()
    for _ in range(steps // substeps):
        hal.send_action(action)
        hal.step(substeps)
        hal.read_state()
    return steps / (time.perf_counter() - start)


def measure(robot_id: str, steps: int, repeats: int, substeps: int) -> dict[str, float | str]:
    """Best-of-``repeats`` rates of the raw and HAL loops, interleaved, on one model."""
    hal = MujocoArmHAL.from_description(load_robot_by_id(robot_id))
    hal.connect()
    model, data = hal.mujoco_handles()
    raw, every_step, control_rate = [], [], []
    for _ in range(repeats):
        raw.append(raw_rate(model, data, steps))
        every_step.append(hal_rate(hal, steps, 1))
        control_rate.append(hal_rate(hal, steps, substeps))
    best_raw = max(raw)
    dt = float(model.opt.timestep)
    return {
        "robot": robot_id,
        "timestep_s": dt,
        "raw_steps_per_s": round(best_raw),
        "hal_steps_per_s": round(max(every_step)),
        "ratio": round(best_raw / max(every_step), 3),
        "control_hz": round(1.0 / (dt * substeps), 1),
        "hal_control_steps_per_s": round(max(control_rate)),
        "control_ratio": round(best_raw / max(control_rate), 3),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=3000, help="steps per timed loop")
    parser.add_argument("--repeats", type=int, default=5, help="interleaved repetitions")
    parser.add_argument(
        "--substeps", type=int, default=10, help="physics steps per action at control rate"
    )
    parser.add_argument("robots", nargs="*", help="robot ids (default: all)")
    args = parser.parse_args()
    robots = args.robots or robot_ids()
    rows = [
        measure(r, args.steps, args.repeats, args.substeps)
        for r in track(robots, description="bench")
    ]
    table = Table(
        title=f"HAL loop vs raw mj_step ({args.steps} physics steps, best of {args.repeats})"
    )
    n = args.substeps
    columns = ("robot", "raw/s", "HAL@1/s", "ratio@1", f"HAL@{n}/s", "ctl Hz", f"ratio@{n}")
    for column in (*columns, "targets"):
        table.add_column(column, justify="left" if column == "robot" else "right")
    for row in rows:
        robot = str(row["robot"])
        at_one = TARGET_AT_ONE.get(robot)
        at_control = TARGET_AT_CONTROL.get(robot, DEFAULT_TARGET_AT_CONTROL)
        ok = at_one is None or float(row["ratio"]) <= at_one
        ok_control = float(row["control_ratio"]) <= at_control
        table.add_row(
            robot,
            f"{row['raw_steps_per_s']:,}",
            f"{row['hal_steps_per_s']:,}",
            f"[{'green' if ok else 'red'}]{row['ratio']:.3f}[/]",
            f"{row['hal_control_steps_per_s']:,}",
            f"{row['control_hz']:g}",
            f"[{'green' if ok_control else 'red'}]{row['control_ratio']:.3f}[/]",
            f"≤ {at_one} / ≤ {at_control}" if at_one else f"- / ≤ {at_control}",
        )
    Console().print(table)
    path = write_results(
        "hal_step",
        {"steps": args.steps, "repeats": args.repeats, "substeps": args.substeps, "results": rows},
    )
    Console().print(
        f"@1: one physics step per action; @{n}: {n} steps per action (a control loop). "
        f"Physics steps per second in both; ratio = raw / HAL. Written to {path}."
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
