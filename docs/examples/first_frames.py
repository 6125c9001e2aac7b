"""Tile the first frame of each sweep video into one PNG, and say whether they differ.

    python docs/examples/first_frames.py out/seeds/videos out/first_frames.png

Each seed of a randomised scene starts differently (the cube moved, turned, recoloured), so
no two first frames should be equal.
"""

from __future__ import annotations

import sys
from itertools import combinations
from pathlib import Path

import imageio_ffmpeg
import numpy as np
from openral_mujoco.png import write_png


def first_frame(video: Path) -> np.ndarray:
    """The first frame of an MP4 as an H x W x 3 uint8 array."""
    reader = imageio_ffmpeg.read_frames(str(video))
    meta = next(reader)
    width, height = meta["size"]
    frame = np.frombuffer(next(reader), dtype=np.uint8).reshape(height, width, 3)
    reader.close()
    return frame


def main() -> None:
    folder, target = Path(sys.argv[1]), Path(sys.argv[2])
    videos = sorted(folder.glob("*.mp4"), key=lambda p: int(p.stem.rsplit("seed", 1)[1]))
    frames = [first_frame(video) for video in videos]
    differ = all(
        np.abs(a.astype(int) - b.astype(int)).mean() > 0.5 for a, b in combinations(frames, 2)
    )
    target.parent.mkdir(parents=True, exist_ok=True)
    write_png(target, np.concatenate(frames, axis=1))
    seeds = ", ".join(video.stem.rsplit("seed", 1)[1] for video in videos)
    print(f"wrote {target} ({len(frames)} first frames: seeds {seeds}); all differ: {differ}")


if __name__ == "__main__":
    main()
