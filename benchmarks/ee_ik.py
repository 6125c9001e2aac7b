"""End-effector actions on the Panda tabletop: what one IK tick costs and how the TCP moves.

The env in ``ee_delta_pose`` (robosuite preset: full scale 0.05 m a step) is given 20 steps
of +x 0.2, then 20 of -z 0.2 (1 cm a step each), ``--rounds`` times from fresh resets. Timed:
the whole end-effector tick (:meth:`EeCommand.delta`: the IK's QP and the reach check), not
the physics. Measured on the TCP the env observes: each step's move along the commanded
axis, the orientation's drift from the start, and the largest joint speed over its limit.
Run with ``just bench-ik``.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np
from openral_core.models import LimitedJoint
from openral_core.paths import repo_root
from openral_eval.scene_env import SceneEnv, make_env
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results

SCENE = repo_root() / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
TARGET_MEDIAN_MS = 0.3


def _angle(q: np.ndarray, r: np.ndarray) -> float:
    return float(2 * np.arccos(min(1.0, abs(float(np.dot(q, r))))))


def one_round(env: SceneEnv, timings: list[float]) -> dict[str, list[float]]:
    """Moves [m] per step along the commanded axis, orientation drift [rad] and joint
    speed over limit per step, for one +x then -z pass; ``timings`` gets each IK tick [s]."""
    ee = env.actions.ee
    assert ee is not None
    delta = ee.delta

    def timed(*args: object) -> object:
        start = time.perf_counter()
        result = delta(*args)  # type: ignore[arg-type]
        timings.append(time.perf_counter() - start)
        return result

    ee.delta = timed  # type: ignore[method-assign]
    speeds = np.array(
        [j.velocity_limit for j in env.robot.description.joints if isinstance(j, LimitedJoint)][:7]
    )
    obs, _ = env.reset(seed=0)
    start = obs["observation.tcp_pose"]
    out: dict[str, list[float]] = {"move_m": [], "turn_rad": [], "speed_ratio": []}
    previous = start[:3]
    try:
        for axis, sign in ((0, 1.0), (2, -1.0)):
            action = np.zeros(7)
            action[axis], action[6] = 0.2 * sign, -1.0
            for _ in range(20):
                obs, *_ = env.step(action)
                tcp = obs["observation.tcp_pose"]
                out["move_m"].append(float((tcp[axis] - previous[axis]) * sign))
                previous = tcp[:3]
                out["turn_rad"].append(_angle(tcp[3:], start[3:]))
                ratio = np.abs(obs["observation.velocity"][:7]) / speeds
                out["speed_ratio"].append(float(ratio.max()))
    finally:
        ee.delta = delta  # type: ignore[method-assign]
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=5, help="passes from fresh resets")
    args = parser.parse_args()
    console = Console()
    env = make_env(SCENE, action_mode="ee_delta_pose", sensors=False)
    timings: list[float] = []
    try:
        rounds = [one_round(env, timings) for _ in range(args.rounds)]
    finally:
        env.close()
    moves = np.array([r["move_m"] for r in rounds])
    turns = np.array([r["turn_rad"] for r in rounds]).max()
    speed = np.array([r["speed_ratio"] for r in rounds]).max()
    ms = np.array(timings) * 1e3
    off = np.abs(moves - 0.01)
    table = Table(
        title=f"Panda tabletop, ee_delta_pose (robosuite), {args.rounds} rounds of 20 +x, 20 -z"
    )
    table.add_column("measure")
    table.add_column("value", justify="right")
    colour = "green" if np.median(ms) <= TARGET_MEDIAN_MS else "red"
    table.add_row("IK tick median", f"[{colour}]{np.median(ms):.3f} ms[/]")
    table.add_row("IK tick 90th percentile", f"{np.percentile(ms, 90):.3f} ms")
    for name, part in (("+x", off[:, :20]), ("-z", off[:, 20:])):
        worst = int(np.argmax(part.max(axis=0))) + 1
        table.add_row(
            f"{name}: steps within 2 mm of 1 cm", f"{int((part <= 0.002).sum())}/{part.size}"
        )
        table.add_row(f"{name}: largest miss (step {worst})", f"{part.max() * 1e3:.2f} mm")
    table.add_row("orientation drift, largest", f"{turns:.4f} rad")
    table.add_row("joint speed / limit, largest", f"{speed:.3f}")
    console.print(table)
    path = write_results(
        "ee_ik",
        {
            "rounds": args.rounds,
            "ik_median_ms": float(np.median(ms)),
            "ik_p90_ms": float(np.percentile(ms, 90)),
            "moves_m": moves.tolist(),
            "largest_turn_rad": float(turns),
            "largest_speed_ratio": float(speed),
        },
    )
    console.print(f"target: IK median ≤ {TARGET_MEDIAN_MS} ms. Written to {path}.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
