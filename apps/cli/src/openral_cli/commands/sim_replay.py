"""``openral sim replay``: re-run one episode of a sweep's dataset from its seed and check
it against the sweep (:mod:`openral_eval.replay`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from openral_core.errors import OpenralError

from openral_cli.console import out


def replay(
    dataset: Annotated[
        Path, typer.Argument(help="Dataset folder written by `sim sweep --dataset`.")
    ],
    episode: Annotated[int, typer.Option("--episode", min=0, help="Episode index to replay.")],
) -> None:
    """Replay EPISODE of DATASET: reset its scene with its seed, step the dataset's actions,
    and compare the joint trajectory's digest with the one the sweep recorded. Exits 1 when
    they differ.

    Example:

        openral sim replay o/ds --episode 3
    """
    from openral_eval.replay import replay as replay_episode

    done = replay_episode(dataset, episode)
    where = f"episode {episode} ({done.scene}, seed {done.seed}): {done.steps} steps replayed"
    if not done.matches:
        raise OpenralError(
            f"{where}; the trajectory differs from the sweep's "
            f"(digest {done.digest[:12]}…, the sweep's {done.expected[:12]}…)"
        )
    same = f"the trajectory matches the sweep's (digest {done.digest[:12]}…)"
    out.print(f"{where}; {same}", markup=False)
