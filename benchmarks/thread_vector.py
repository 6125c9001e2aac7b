"""The threaded vector env of 2 against its ceiling, measured in the same run: two threads
of bare ``mj_step`` (each on a scene of its own, a control period of physics steps per
call) against one thread, on franka_panda's tabletop with cameras off. Used by
``just bench-env`` (:mod:`benchmarks.env_step`)."""

from __future__ import annotations

import threading
import time

import mujoco
from openral_eval.scene_env import make_env, make_thread_vector_env
from rich.table import Table

from benchmarks.step_rate import best_rates

MIN_SHARE_OF_CEILING = 0.9
"""The threaded vector env's gain over one env, as a share of the bare threads' gain."""
LONG = 10**9
"""A step limit no run reaches (an autoreset inside a timed run would be timed too)."""


def _bare_rate(
    handles: list[tuple[mujoco.MjModel, mujoco.MjData]], substeps: int, steps: int
) -> float:
    """Control periods per second summed over ``handles``, each stepped on a thread."""

    def run(model: mujoco.MjModel, data: mujoco.MjData) -> None:
        for _ in range(steps):
            mujoco.mj_step(model, data, nstep=substeps)

    threads = [threading.Thread(target=run, args=pair) for pair in handles]
    began = time.perf_counter()
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return len(handles) * steps / (time.perf_counter() - began)


def bare_ceiling(scene: str, steps: int, repeats: int) -> float:
    """Two bare MuJoCo threads' periods/s over one thread's (best of ``repeats``)."""
    envs = [make_env(scene, sensors=False) for _ in range(2)]
    try:
        pairs = [h for h in (env.hal.mujoco_handles() for env in envs) if h is not None]
        substeps = round(envs[0].hal.control_period_s / float(pairs[0][0].opt.timestep))
        one = max(_bare_rate(pairs[:1], substeps, steps) for _ in range(repeats))
        two = max(_bare_rate(pairs, substeps, steps) for _ in range(repeats))
        return two / one
    finally:
        for env in envs:
            env.close()


def thread_speedup(scene: str, steps: int, repeats: int) -> tuple[float, float]:
    """(one env's steps/s, the threaded vector env of 2's env steps/s), cameras off
    (:func:`~benchmarks.step_rate.best_rates`)."""
    vector = make_thread_vector_env(scene, 2, sensors=False, max_steps=LONG)
    single = make_env(scene, sensors=False, max_steps=LONG)
    try:
        vector.reset(seed=[0, 1])
        single.reset(seed=0)
        return best_rates(single, vector, single.hal.hold_action(), steps, repeats)
    finally:
        vector.close()
        single.close()


def add_thread_rows(table: Table, one: float, two: float, bare: float) -> float:
    """Add the threaded vector env's rows to ``table``; its share of the ceiling."""
    share = (two / one) / bare
    colour = "green" if share >= MIN_SHARE_OF_CEILING else "red"
    table.add_row("one env (threads run), cameras off", "", f"{one:.0f}", "1.00x")
    table.add_row(
        "ThreadVectorEnv x2, cameras off", "", f"{two:.0f}",
        f"[{colour}]{two / one:.2f}x ({share:.0%} of the ceiling)[/]",
    )  # fmt: skip
    table.add_row("ceiling: 2 threads of bare mj_step", "", "", f"{bare:.2f}x")
    return share
