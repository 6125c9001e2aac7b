"""Synthetic episodes for the LeRobot dataset tests, and readers of what was written.

Three episodes (12, 9 and 15 frames at 10 Hz; 9 state and 8 action entries; two 64x48
cameras whose pictures move every frame; two tasks).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import imageio_ffmpeg
import numpy as np
import numpy.typing as npt
import pyarrow.parquet as pq
from openral_eval.lerobot_dataset import (
    DatasetEpisode,
    DatasetLayout,
)

FPS = 10.0
HEIGHT, WIDTH = 48, 64
SPECS = ((12, "lift the red cube"), (9, "push the block"), (15, "lift the red cube"))
LAYOUT = DatasetLayout(
    fps=FPS,
    robot_type="franka_panda",
    state_names=(*(f"joint{i}" for i in range(7)), "finger_left", "finger_right"),
    action_names=(*(f"joint{i}" for i in range(7)), "gripper"),
    cameras=("front", "wrist"),
)
QUANTILES = {"q01": 0.01, "q10": 0.10, "q50": 0.50, "q90": 0.90, "q99": 0.99}
VECTOR_STATS = ("min", "max", "mean", "std", *QUANTILES)


def _pictures(length: int, seed: int) -> npt.NDArray[np.uint8]:
    """Smooth colour waves that travel a twelfth of their period every frame."""
    y, x = np.mgrid[0:HEIGHT, 0:WIDTH] / np.array([HEIGHT, WIDTH])[:, None, None]
    frames = np.empty((length, HEIGHT, WIDTH, 3), dtype=np.uint8)
    for t in range(length):
        shift = 2 * np.pi * (t / 12 + seed / 5)
        frames[t, ..., 0] = 127 + 100 * np.sin(2 * np.pi * x + shift)
        frames[t, ..., 1] = 127 + 100 * np.cos(2 * np.pi * y * 0.8 - shift)
        frames[t, ..., 2] = 127 + 80 * np.sin(2 * np.pi * (x + y) + 2 * shift)
    return frames


def _episode(index: int) -> DatasetEpisode:
    length, task = SPECS[index]
    rng = np.random.default_rng(index)
    success = np.zeros(length, dtype=bool)
    success[-3:] = index != 1  # episode 1 fails
    return DatasetEpisode(
        task=task,
        states=rng.normal(0.0, 1.0, (length, 9)).astype(np.float32),
        actions=rng.uniform(-1.0, 1.0, (length, 8)).astype(np.float32),
        success=success,
        frames={"front": _pictures(length, index), "wrist": _pictures(length, index + 3)},
    )


EPISODES = [_episode(i) for i in range(len(SPECS))]


def _info(folder: Path) -> dict[str, object]:
    info: dict[str, object] = json.loads((folder / "meta" / "info.json").read_text())
    return info


def _episode_rows(folder: Path) -> list[dict[str, object]]:
    rows: list[dict[str, object]] = pq.read_table(
        folder / "meta/episodes/chunk-000/file-000.parquet"
    ).to_pylist()
    return rows


def _video(folder: Path, slot: str) -> Path:
    return folder / f"videos/observation.images.{slot}/chunk-000/file-000.mp4"


def _decode(path: Path) -> tuple[npt.NDArray[np.uint8], list[float] | None]:
    """Every frame of an MP4 as RGB, and their times [s] (PyAV, else ffmpeg with no times)."""
    try:
        import av
    except ImportError:
        exe = imageio_ffmpeg.get_ffmpeg_exe()
        command = [exe, "-v", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", "rgb24", "-"]
        raw = subprocess.run(command, capture_output=True, check=True).stdout
        return np.frombuffer(raw, dtype=np.uint8).reshape(-1, HEIGHT, WIDTH, 3), None
    with av.open(str(path)) as container:
        frames = list(container.decode(video=0))
        pictures = np.stack([frame.to_ndarray(format="rgb24") for frame in frames]).astype(np.uint8)
        return pictures, [float(frame.time) for frame in frames]


DATA_COLUMNS = (
    "observation.state",
    "action",
    "next.success",
    "timestamp",
    "frame_index",
    "episode_index",
    "index",
    "task_index",
)
"""The data file's columns, in LeRobot's order."""


def doctor(folder: Path) -> tuple[dict[str, Any], list[str]]:
    """lerobot-doctor's JSON report on ``folder`` (it must exit 0) and its FAIL messages."""
    executable = Path(sys.executable).parent / "lerobot-doctor"
    run = subprocess.run(
        [str(executable), "check", str(folder), "--ci", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    report: dict[str, Any] = json.loads(run.stdout)
    failures = [
        f"{check['name']}: {message['message']}"
        for check in report["checks"]
        for message in check["messages"]
        if message["severity"] == "FAIL"
    ]
    return report, failures
