"""Success rates per scene with 95 % Wilson score intervals (``summary.json``).

The Wilson interval keeps to [0, 1] and stays informative at 0 or n successes out of n,
where the normal approximation collapses to a point; with n episodes and k successes,
p = k/n and z = 1.96:

    centre = (p + z²/2n) / (1 + z²/n),  half = z·sqrt(p(1-p)/n + z²/4n²) / (1 + z²/n).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass

Z_95 = 1.959963984540054
"""The normal quantile of a two-sided 95 % interval."""


def wilson(successes: int, trials: int, z: float = Z_95) -> tuple[float, float]:
    """The Wilson score interval (low, high) of ``successes`` in ``trials`` (0, 1 when
    there are none)."""
    if trials <= 0:
        return 0.0, 1.0
    p = successes / trials
    scale = 1.0 + z * z / trials
    centre = (p + z * z / (2 * trials)) / scale
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / scale
    return max(0.0, centre - half), min(1.0, centre + half)


@dataclass(frozen=True)
class SceneSummary:
    """One scene's outcome over its episodes."""

    scene: str
    episodes: int
    successes: int
    errors: int
    success_rate: float
    ci95_low: float
    ci95_high: float
    mean_steps: float
    """Mean control steps of the successful episodes (0 without one)."""


def summarise(lines: Iterable[Mapping[str, object]]) -> list[SceneSummary]:
    """Per scene (in first-seen order), from result lines of ``episodes.jsonl``."""
    by_scene: dict[str, list[Mapping[str, object]]] = {}
    for line in lines:
        by_scene.setdefault(str(line["scene"]), []).append(line)
    rows = []
    for scene, episodes in by_scene.items():
        won = [e for e in episodes if e.get("success") is True]
        steps = [float(str(e.get("steps", 0))) for e in won]
        low, high = wilson(len(won), len(episodes))
        rows.append(
            SceneSummary(
                scene=scene,
                episodes=len(episodes),
                successes=len(won),
                errors=sum(1 for e in episodes if e.get("error")),
                success_rate=len(won) / len(episodes),
                ci95_low=low,
                ci95_high=high,
                mean_steps=sum(steps) / len(steps) if steps else 0.0,
            )
        )
    return rows


def summary_json(rows: Iterable[SceneSummary], policy: str) -> dict[str, object]:
    """What ``summary.json`` holds."""
    return {"policy": policy, "interval": "Wilson score, 95 %", "scenes": [asdict(r) for r in rows]}
