"""Scene step rate: SimAttachedHAL on the native franka tabletop against robosuite Lift.

Both scenes come from the committed scene files of franka_panda (``tabletop.yaml``, native;
``lift_robosuite.yaml``, robosuite), with the same two cameras (agentview, wrist) at the
same resolution and the same 20 Hz control period. One loop iteration is what the deploy
node does per control tick: ``send_action(hold_action())``, ``read_state()``,
``read_images()``. The two backends run interleaved in one process, best of ``--repeats``,
so the ratio cancels out the machine's speed. Run with ``just bench-scene``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

from openral_core import open_robot_by_id
from openral_core.paths import repo_root
from openral_hal.sim_attached import SimAttachedHAL
from openral_sim.scene import build_sim_env_from_yaml
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results

SCENES = {"native": "tabletop.yaml", "robosuite": "lift_robosuite.yaml"}
TARGET_RATIO = 2.0
"""Native steps/s over robosuite steps/s the native backend should reach."""


def attached(scene_file: str) -> SimAttachedHAL:
    """A connected SimAttachedHAL on one of franka_panda's scene files."""
    path = repo_root() / "robots" / "franka_panda" / "scenes" / scene_file
    hal = SimAttachedHAL(build_sim_env_from_yaml(path), open_robot_by_id("franka_panda"))
    hal.connect()
    return hal


def steps_per_s(hal: SimAttachedHAL, steps: int) -> float:
    """Control ticks per second: hold action in, joint state and camera frames out."""
    hold = hal.hold_action()
    start = time.perf_counter()
    for _ in range(steps):
        hal.send_action(hold)
        hal.read_state()
        hal.read_images()
    return steps / (time.perf_counter() - start)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=60, help="timed control ticks per run")
    parser.add_argument("--repeats", type=int, default=3, help="interleaved runs per backend")
    args = parser.parse_args()
    console = Console()
    hals = {name: attached(scene) for name, scene in SCENES.items()}
    try:
        for hal in hals.values():  # warm-up: first renders, robosuite's numba compilation
            steps_per_s(hal, 5)
        best = dict.fromkeys(hals, 0.0)
        with console.status("measuring") as status:
            for repeat in range(args.repeats):
                for name, hal in hals.items():
                    status.update(f"run {repeat + 1}/{args.repeats}: {name}")
                    best[name] = max(best[name], steps_per_s(hal, args.steps))
        image = next(iter(hals["native"].read_images().values()))
        cameras = sorted(hals["native"].read_images())
    finally:
        for hal in hals.values():
            hal.disconnect()
    ratio = best["native"] / best["robosuite"]
    table = Table(
        title=f"franka_panda, cameras {', '.join(cameras)} at {image.shape[1]}x{image.shape[0]}"
        f", 20 Hz control ({args.steps} ticks, best of {args.repeats})"
    )
    for column in ("backend", "scene file", "ticks/s", "ratio"):
        table.add_column(column, justify="left" if column in ("backend", "scene file") else "right")
    table.add_row("robosuite", SCENES["robosuite"], f"{best['robosuite']:.1f}", "1.00")
    colour = "green" if ratio >= TARGET_RATIO else "red"
    table.add_row("native", SCENES["native"], f"{best['native']:.1f}", f"[{colour}]{ratio:.2f}[/]")
    console.print(table)
    path: Path = write_results(
        "scene_step",
        {
            "steps": args.steps,
            "repeats": args.repeats,
            "cameras": cameras,
            "image_shape": list(image.shape),
            "ticks_per_s": best,
            "native_over_robosuite": ratio,
            "target_ratio": TARGET_RATIO,
        },
    )
    console.print(f"target: native ≥ {TARGET_RATIO} x robosuite. Written to {path}.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
