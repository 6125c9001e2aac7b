"""Feature statistics of a LeRobot v3.0 dataset, computed with numpy as LeRobot computes them.

Each feature gets ``min``, ``max``, ``mean``, ``std`` (population), the quantiles ``q01``,
``q10``, ``q50``, ``q90``, ``q99`` and ``count`` (frames, or sampled frames for a camera):

* a vector feature (``(T,)`` or ``(T, n)`` values over ``T`` frames): one value per entry,
  shape ``(1,)`` or ``(n,)``, in the feature's own units;
* a camera (``(T, H, W, 3)`` RGB uint8): one value per channel, shape ``(3, 1, 1)``, pixel
  values divided by 255 (so in [0, 1]), over LeRobot's sample of the episode's frames
  (every frame up to 100, then about ``T**0.75`` evenly spaced ones, at most 10 000; frames
  of 300 px or more are strided down to about 150 px as LeRobot does).

Episodes merge as LeRobot aggregates them: count-weighted mean, pooled variance, the extreme
min and max, and a conservative quantile envelope (the lowest of each quantile up to q50,
the highest above).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Final

import numpy as np
import numpy.typing as npt

QUANTILES: Final = (0.01, 0.10, 0.50, 0.90, 0.99)
"""The quantiles LeRobot stores, as fractions."""

FeatureStats = dict[str, npt.NDArray[np.float64]]
"""One feature's statistics by name (``min``, ``max``, ``mean``, ``std``, ``q01``.., ``count``)."""


def _quantile_key(q: float) -> str:
    return f"q{round(q * 100):02d}"


def vector_stats(values: npt.NDArray[np.generic]) -> FeatureStats:
    """Statistics over the frames (axis 0) of ``(T,)`` or ``(T, n)`` numbers or booleans."""
    data = np.asarray(values, dtype=np.float64).reshape(len(values), -1)
    stats: FeatureStats = {
        "min": data.min(axis=0),
        "max": data.max(axis=0),
        "mean": data.mean(axis=0),
        "std": data.std(axis=0),
    }
    for q in QUANTILES:
        stats[_quantile_key(q)] = np.quantile(data, q, axis=0)
    stats["count"] = np.array([float(len(data))])
    return stats


def sample_indices(frames: int) -> npt.NDArray[np.intp]:
    """LeRobot's sample of an episode's ``frames`` camera frames, as frame indices."""
    wanted = min(100, frames)
    count = max(wanted, min(int(frames**0.75), 10_000))
    return np.round(np.linspace(0, frames - 1, count)).astype(np.intp)


def _downsampled(frames: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
    height, width = frames.shape[1:3]
    if max(height, width) < 300:
        return frames
    step = int(width / 150) if width > height else int(height / 150)
    return frames[:, ::step, ::step]


def _histogram_quantile(cumulative: npt.NDArray[np.int64], q: float) -> float:
    """numpy's linear-interpolation quantile of the values 0..255 counted by ``cumulative``."""
    position = q * (int(cumulative[-1]) - 1)
    below, fraction = int(np.floor(position)), position - np.floor(position)
    low = int(np.searchsorted(cumulative, below, side="right"))
    high = int(np.searchsorted(cumulative, below + 1, side="right")) if fraction else low
    return float(low + fraction * (high - low))


def image_stats(frames: npt.NDArray[np.uint8]) -> FeatureStats:
    """Per-channel statistics of ``(T, H, W, 3)`` RGB frames, scaled to [0, 1] (see module)."""
    sampled = _downsampled(frames[sample_indices(len(frames))])
    channels: dict[str, list[float]] = {}
    for channel in range(3):
        counts = np.bincount(sampled[..., channel].ravel(), minlength=256).astype(np.int64)
        levels = np.arange(256, dtype=np.float64)
        total = float(counts.sum())
        mean = float(counts @ levels) / total
        values = {
            "min": float(np.flatnonzero(counts)[0]),
            "max": float(np.flatnonzero(counts)[-1]),
            "mean": mean,
            "std": float(np.sqrt(counts @ (levels - mean) ** 2 / total)),
        }
        cumulative = np.cumsum(counts)
        for q in QUANTILES:
            values[_quantile_key(q)] = _histogram_quantile(cumulative, q)
        for name, value in values.items():
            channels.setdefault(name, []).append(value / 255.0)
    stats = {name: np.array(v).reshape(3, 1, 1) for name, v in channels.items()}
    stats["count"] = np.array([float(len(sampled))])
    return stats


def merge_stats(first: FeatureStats, second: FeatureStats) -> FeatureStats:
    """The statistics of two disjoint sets of frames, from theirs (LeRobot's aggregation)."""
    n1, n2 = first["count"], second["count"]
    total = n1 + n2
    mean = (first["mean"] * n1 + second["mean"] * n2) / total
    spread1 = (first["std"] ** 2 + (first["mean"] - mean) ** 2) * n1
    spread2 = (second["std"] ** 2 + (second["mean"] - mean) ** 2) * n2
    merged: FeatureStats = {
        "min": np.minimum(first["min"], second["min"]),
        "max": np.maximum(first["max"], second["max"]),
        "mean": mean,
        "std": np.sqrt((spread1 + spread2) / total),
    }
    for q in QUANTILES:
        key = _quantile_key(q)
        pick = np.minimum if q <= 0.5 else np.maximum
        merged[key] = pick(first[key], second[key])
    merged["count"] = total
    return merged


def episode_stats(
    columns: Mapping[str, npt.NDArray[np.generic]], cameras: Mapping[str, npt.NDArray[np.uint8]]
) -> dict[str, FeatureStats]:
    """An episode's statistics: of each frame column, and of each camera's frames."""
    stats = {name: vector_stats(values) for name, values in columns.items()}
    return stats | {key: image_stats(frames) for key, frames in cameras.items()}


def merge_dataset_stats(
    total: Mapping[str, FeatureStats], episode: Mapping[str, FeatureStats]
) -> dict[str, FeatureStats]:
    """The dataset's statistics so far (``total``, empty at first) with one more episode's."""
    return {k: merge_stats(total[k], s) if k in total else s for k, s in episode.items()}


def _plain(name: str, value: npt.NDArray[np.float64]) -> object:
    """A statistic as JSON/parquet values: nested lists of floats, ``count`` as integers."""
    if name == "count":
        return [int(v) for v in value]
    return value.tolist()


def stats_json(stats: Mapping[str, FeatureStats]) -> dict[str, dict[str, object]]:
    """``meta/stats.json``'s content: feature -> statistic -> (nested) list."""
    return {feature: {k: _plain(k, v) for k, v in s.items()} for feature, s in stats.items()}


def stats_columns(stats: Mapping[str, FeatureStats]) -> dict[str, object]:
    """An episode row's ``stats/<feature>/<statistic>`` columns (LeRobot's flattened names)."""
    return {
        f"stats/{feature}/{k}": _plain(k, v) for feature, s in stats.items() for k, v in s.items()
    }
