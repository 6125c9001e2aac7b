"""``openral sim replay``: re-run one episode of a sweep's dataset from its seed and check
it against the sweep (:mod:`openral_eval.replay`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from openral_core.errors import OpenralError

from openral_cli.browser_view import (
    DEFAULT_VIEW_PORT,
    View,
    ViewPort,
    open_view,
    serve_until_interrupted,
)
from openral_cli.console import out

if TYPE_CHECKING:
    from openral_hal.protocol import RobotHal
    from openral_hal.view_feed import ViewFeed


def replay(
    dataset: Annotated[
        Path,
        typer.Argument(help="A dataset (`sim sweep --dataset`) or a sweep's --out folder."),
    ],
    episode: Annotated[int, typer.Option("--episode", min=0, help="Episode index to replay.")],
    video: Annotated[
        Path | None,
        typer.Option("--video", help="Render the replay's first camera to this MP4 file."),
    ] = None,
    view: View = False,
    view_port: ViewPort = DEFAULT_VIEW_PORT,
) -> None:
    """Replay EPISODE of DATASET: reset its scene with its seed, step the dataset's actions
    (for a sweep's results folder: run its policy again), and compare the joint
    trajectory's digest with the one the sweep recorded. Exits 1 when they differ.

    Example:

        openral sim replay o/ds --episode 3 --video o/ep3.mp4
    """
    from openral_eval.replay import PROVENANCE, replay_sweep
    from openral_eval.replay import replay as replay_episode

    feeds: list[ViewFeed] = []

    def open_feed(hal: RobotHal) -> ViewFeed:
        feeds.append(open_view(hal, f"{dataset} · episode {episode}", view_port))
        return feeds[-1]

    if (dataset / PROVENANCE).is_file() or not (dataset / "episodes.jsonl").is_file():
        done = replay_episode(dataset, episode, video=video, view=open_feed if view else None)
    else:
        done = replay_sweep(dataset, episode, video=video, view=open_feed if view else None)
    if video is not None:
        frames = f" ({done.frames} frames)" if done.frames else ""
        out.print(f"video: {video}{frames}", markup=False)
    where = f"episode {episode} ({done.scene}, seed {done.seed}): {done.steps} steps replayed"
    if not done.matches:
        raise OpenralError(
            f"{where}; the trajectory differs from the sweep's "
            f"(digest {done.digest[:12]}…, the sweep's {done.expected[:12]}…)"
        )
    same = f"the trajectory matches the sweep's (digest {done.digest[:12]}…)"
    out.print(f"{where}; {same}", markup=False)
    for feed in feeds:
        serve_until_interrupted(feed)
