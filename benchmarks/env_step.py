"""The gymnasium env's cost: its step against the native scene's own step, and a vector env
of 2 against one env.

On franka_panda's tabletop (20 Hz control): the scene's own ``step(hold)`` on the rollout
the env wraps, against ``SceneEnv.step(hold)`` (the action check, the HAL, the Dict
observation), both with cameras off and with both cameras on: ``--pairs`` back-to-back
blocks of each, the overhead from the median of the pairs' ratios. Then
``gymnasium.vector.AsyncVectorEnv`` of 2 (cameras off, one process per env) against one
env in this process: env steps per second summed over the envs, beside the ratio
gymnasium's own inter-process steps allow for an env that only burns the same time per
step (the ceiling: pipes, pickling and the merging of ``info``). Run with ``just
bench-env``.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium
import numpy as np
from openral_core.paths import repo_root
from openral_eval.scene_env import ENV_ID, SceneEnv, make_env
from openral_sim.rollout import SceneRollout
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results
from benchmarks.step_rate import best_rates, rate
from benchmarks.thread_vector import (
    MIN_SHARE_OF_CEILING,
    add_vector_row,
    bare_ceiling,
)
from benchmarks.thread_vector import (
    speedup as vector_gain,
)

SCENE = str(repo_root() / "robots" / "franka_panda" / "scenes" / "tabletop.yaml")
MAX_OVERHEAD = 0.05
"""Env step time over the scene's own step time, minus 1, at most."""
MIN_VECTOR_SPEEDUP = 1.7
"""Env steps/s of a vector env of 2 over one env, at least."""


def step_rates(env: SceneEnv, steps: int, pairs: int) -> tuple[float, float]:
    """(scene steps/s, env steps/s): the medians over ``pairs`` back-to-back blocks of
    ``steps`` of each, their order swapped every pair (what the machine does meanwhile
    slows both of a pair alike; a median of pairs, not the best of each, so one quiet
    moment on one side does not decide the ratio)."""
    scene = env.hal.env
    if not isinstance(scene, SceneRollout):
        raise TypeError("the tabletop is a native scene")
    hold = env.hal.hold_action()
    env.reset(seed=0)
    scene_rates, env_rates = [], []
    for pair in range(pairs):
        scene_first = pair % 2 == 0
        timed = {}
        for side in ("scene", "env") if scene_first else ("env", "scene"):
            timed[side] = _block(scene if side == "scene" else env, hold, steps)
        scene_rates.append(timed["scene"])
        env_rates.append(timed["env"])
    ratios = np.array(scene_rates) / np.array(env_rates)
    median_scene = float(np.median(scene_rates))
    return median_scene, median_scene / float(np.median(ratios))


def _block(stepper: SceneRollout | SceneEnv, hold: np.ndarray, steps: int) -> float:
    """Steps/s of ``steps`` of ``stepper.step(hold)``."""
    return rate(lambda: stepper.step(hold), steps)


class BusyEnv(gymnasium.Env[dict[str, np.ndarray], np.ndarray]):
    """gymnasium's own ceiling: an env that only keeps a core busy for ``cost_s`` per step
    and returns observations like the scene env's (cameras off)."""

    def __init__(self, cost_s: float, like: SceneEnv) -> None:
        self.cost_s = cost_s
        self.observation_space = like.layout.space
        self.action_space = like.box
        self.obs, _ = like.reset(seed=0)

    def reset(self, *, seed: int | None = None, options: object = None) -> tuple[object, dict]:
        super().reset(seed=seed)
        return self.obs, {"seed": 0, "success": False}

    def step(self, action: np.ndarray) -> tuple[object, float, bool, bool, dict]:
        end = time.perf_counter() + self.cost_s
        while time.perf_counter() < end:
            pass
        return self.obs, 0.0, False, False, {"success": False}


def ceiling(cost_s: float, steps: int, repeats: int) -> float:
    """What an AsyncVectorEnv of 2 gains over one env when a step costs ``cost_s`` [s] and
    does nothing else: the ratio gymnasium's inter-process steps allow here."""
    like = make_env(SCENE, sensors=False)
    envs = [BusyEnv(cost_s, like) for _ in range(3)]
    like.close()
    vector = gymnasium.vector.AsyncVectorEnv([lambda: envs[1], lambda: envs[2]])
    try:
        vector.reset(seed=[0, 1])
        action = envs[0].action_space.sample()
        both = np.stack([action] * 2)
        one = max(rate(lambda: envs[0].step(action), steps) for _ in range(repeats))
        two = max(2 * rate(lambda: vector.step(both), steps) for _ in range(repeats))
        return two / one
    finally:
        vector.close()


def vector_speedup(steps: int, repeats: int) -> tuple[float, float]:
    """(one env's steps/s, an AsyncVectorEnv of 2's env steps/s), cameras off
    (:func:`~benchmarks.step_rate.best_rates`)."""
    config = {"scene": SCENE, "sensors": False}
    vector = gymnasium.vector.AsyncVectorEnv([lambda: gymnasium.make(ENV_ID, config=config)] * 2)
    single = make_env(SCENE, sensors=False)
    try:
        vector.reset(seed=[0, 1])
        single.reset(seed=0)
        return best_rates(single, vector, single.hal.hold_action(), steps, repeats)
    finally:
        vector.close()
        single.close()


def _args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=400, help="timed steps per run")
    parser.add_argument("--repeats", type=int, default=5, help="interleaved vector-env runs")
    parser.add_argument("--pairs", type=int, default=30, help="scene/env block pairs")
    return parser.parse_args()


def _table(args: argparse.Namespace) -> Table:
    table = Table(
        title=f"franka_panda tabletop, 20 Hz control (env: median of {args.pairs} pairs; "
        f"vector: best of {args.repeats})"
    )
    for column in ("case", "scene steps/s", "env steps/s", "env overhead"):
        table.add_column(column, justify="left" if column == "case" else "right")
    return table


def _env_rates(args: argparse.Namespace) -> dict[str, tuple[float, float]]:
    """(scene steps/s, env steps/s) with cameras off and on."""
    rates: dict[str, tuple[float, float]] = {}
    for label, sensors in (("cameras off", False), ("2 cameras on", True)):
        env = make_env(SCENE, sensors=sensors)
        steps = args.steps // 4 if sensors is False else args.steps // 40
        rates[label] = step_rates(env, steps, args.pairs)
        env.close()
    return rates


def main() -> int:
    args = _args()
    console = Console()
    with console.status("measuring the env step"):
        rates = _env_rates(args)
    with console.status("measuring a vector env of 2"):
        one, two = vector_speedup(args.steps, args.repeats)
        bound = ceiling(1.0 / one, args.steps, args.repeats)
    with console.status("measuring the threaded and process vector envs of 2, bare threads"):
        t_one, t_two = vector_gain(SCENE, args.steps, args.repeats, processes=False)
        p_one, p_two = vector_gain(SCENE, args.steps, args.repeats, processes=True)
        bare = bare_ceiling(SCENE, args.steps, args.repeats)
    table = _table(args)
    overheads = {}
    for label, (scene_rate, env_rate) in rates.items():
        overheads[label] = scene_rate / env_rate - 1.0
        colour = "green" if overheads[label] <= MAX_OVERHEAD else "red"
        table.add_row(
            label, f"{scene_rate:.0f}", f"{env_rate:.0f}", f"[{colour}]{overheads[label]:+.1%}[/]"
        )
    speedup = two / one
    colour = "green" if speedup >= MIN_VECTOR_SPEEDUP else "red"
    table.add_row("one env, cameras off", "", f"{one:.0f}", "1.00x")
    table.add_row(
        "AsyncVectorEnv x2, cameras off", "", f"{two:.0f}", f"[{colour}]{speedup:.2f}x[/]"
    )
    table.add_row(f"gymnasium's ceiling at {1e3 / one:.2f} ms per step", "", "", f"{bound:.2f}x")
    share = add_vector_row(table, "ThreadVectorEnv", t_one, t_two, bare)
    process_share = add_vector_row(table, "ProcessVectorEnv", p_one, p_two, bare)
    table.add_row("ceiling: 2 threads of bare mj_step", "", "", f"{bare:.2f}x")
    console.print(table)
    path = write_results(
        "env_step",
        {
            "steps": args.steps,
            "repeats": args.repeats,
            "pairs": args.pairs,
            "rates": {k: {"scene": s, "env": e} for k, (s, e) in rates.items()},
            "overhead": overheads,
            "one_env_steps_per_s": one,
            "vector_2_steps_per_s": two,
            "vector_speedup": speedup,
            "vector_ceiling_same_step_cost": bound,
            "thread_vector_one_env_steps_per_s": t_one,
            "thread_vector_2_steps_per_s": t_two,
            "bare_mujoco_threads_ceiling": bare,
            "thread_vector_share_of_ceiling": share,
            "process_vector_one_env_steps_per_s": p_one,
            "process_vector_2_steps_per_s": p_two,
            "process_vector_share_of_ceiling": process_share,
        },
    )
    console.print(
        f"targets: env overhead ≤ {MAX_OVERHEAD:.0%}, vector of 2 ≥ {MIN_VECTOR_SPEEDUP}x one env,"
        f" process vector of 2 ≥ {MIN_SHARE_OF_CEILING:.0%} of the bare-thread ceiling."
        f" Written to {path}."
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
