"""The evaluation guide's pictures of a ``scripted_lift`` sweep, drawn from its own videos.

``python -m tests.docs.sweep_pictures`` (from the repository root; ``just
docs-sweep-images``) runs seeds 0 to 3 of the franka tabletop with ``scripted_lift``,
each filmed by the scene's first camera (10 Hz), and writes two strips of four frames:
``docs/images/sweep_lift_seed0.png`` (seed 0 at control steps 0, 25, 40 and 60) and
``docs/images/sweep_first_frames.png`` (the first frame of seeds 0 to 3).
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import av
import numpy as np
from openral_eval.episode import EpisodeSpec, close_scenes, run_episode
from PIL import Image

REPO = Path(__file__).resolve().parents[2]
SCENE = "robots/franka_panda/scenes/tabletop.yaml"
STEPS = (0, 25, 40, 60)
"""Control steps of seed 0's strip (20 Hz control, 10 Hz camera: frame = step // 2)."""
SEEDS = (0, 1, 2, 3)


def _frames(video: Path) -> list[np.ndarray]:
    with av.open(str(video)) as container:
        return [frame.to_ndarray(format="rgb24") for frame in container.decode(video=0)]


def _strip(frames: list[np.ndarray], path: Path) -> None:
    Image.fromarray(np.concatenate(frames, axis=1)).save(path)
    print(f"wrote {path.relative_to(REPO)}")


def main() -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    images = REPO / "docs" / "images"
    with tempfile.TemporaryDirectory() as folder:
        videos = {}
        try:
            for seed in SEEDS:
                video = Path(folder) / f"seed{seed}.mp4"
                spec = EpisodeSpec(scene=SCENE, seed=seed, policy="scripted_lift", video=str(video))
                result = run_episode(spec)
                if not result.success:
                    print(f"seed {seed} did not lift the cube: {result}", file=sys.stderr)
                    return 1
                videos[seed] = _frames(video)
        finally:
            close_scenes()  # its renderers, while their GL display is still open
        _strip([videos[0][step // 2] for step in STEPS], images / "sweep_lift_seed0.png")
        _strip([videos[seed][0] for seed in SEEDS], images / "sweep_first_frames.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
