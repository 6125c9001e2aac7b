"""The threaded and the process vector envs of 2 against their ceiling, measured in the
same run: two threads of bare ``mj_step`` (each on a scene of its own, a control period of
physics steps per call) against one thread, on franka_panda's tabletop with cameras off.
Used by ``just bench-env`` (:mod:`benchmarks.env_step`)."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import mujoco
from openral_eval.scene_env import make_env
from openral_eval.vector_envs import make_process_vector_env, make_thread_vector_env
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


def speedup(scene: str, steps: int, repeats: int, *, processes: bool) -> tuple[float, float]:
    """(one env's steps/s, a vector env of 2's env steps/s), cameras off: the threaded one,
    or with ``processes`` the process one (:func:`~benchmarks.step_rate.best_rates`)."""
    make: Callable[..., Any] = make_process_vector_env if processes else make_thread_vector_env
    vector = make(scene, 2, sensors=False, max_steps=LONG)
    single = make_env(scene, sensors=False, max_steps=LONG)
    try:
        vector.reset(seed=[0, 1])
        single.reset(seed=0)
        return best_rates(single, vector, single.hal.hold_action(), steps, repeats)
    finally:
        vector.close()
        single.close()


def add_vector_row(table: Table, label: str, one: float, two: float, bare: float) -> float:
    """Add a vector env's row (its gain over one env, measured in its own run) to
    ``table``; its share of the ceiling."""
    share = (two / one) / bare
    colour = "green" if share >= MIN_SHARE_OF_CEILING else "red"
    table.add_row(
        f"{label} x2, cameras off", "", f"{two:.0f}",
        f"[{colour}]{two / one:.2f}x ({share:.0%} of the ceiling)[/]",
    )  # fmt: skip
    return share
