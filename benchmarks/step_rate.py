"""Steps per second of an env and of a vector env of 2, timed alike (for ``bench-env``)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt


def rate(step: Callable[[], object], steps: int) -> float:
    """Calls of ``step`` per second."""
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return steps / (time.perf_counter() - start)


def best_rates(
    single: Any, vector: Any, hold: npt.NDArray[np.float64], steps: int, repeats: int
) -> tuple[float, float]:
    """(one env's steps/s, the vector env of 2's env steps/s) holding ``hold``, best of
    ``repeats`` runs of each, interleaved (the machine's load changes both alike)."""
    both = np.stack([hold] * 2)
    best_one = best_two = 0.0
    for _ in range(repeats):
        best_one = max(best_one, rate(lambda: single.step(hold), steps))
        best_two = max(best_two, 2 * rate(lambda: vector.step(both), steps))
    return best_one, best_two
