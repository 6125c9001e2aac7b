"""``openral sim run --policy``: one episode of a policy on a scene, as a sweep runs it.

The episode is the sweep's (:func:`openral_eval.episode.run_episode`): the scene reset with
``--seed``, the policy's actions (joint targets or end-effector deltas, as it declares)
stepping the scene's gymnasium env, ending on success, the scene's horizon or ``--steps``.
With ``--out`` it writes ``episode.json`` (the sweep's line for it) and ``episode.mp4`` (the
scene's first camera).
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import typer

from openral_cli.browser_view import open_view, serve_until_interrupted
from openral_cli.commands.sweep import check_out_dir
from openral_cli.console import out


def run_policy(
    config: Path,
    policy: str,
    params: list[str],
    seed: int,
    steps: int | None,
    out_dir: Path | None,
    view_port: int | None = None,
) -> None:
    """Run one episode and print what it did (exit 1 when it ended with an error); with a
    ``view_port``, draw it in the browser view and keep that up afterwards."""
    from openral_eval.episode import EpisodeSpec, close_scenes, run_episode, scene_for
    from openral_eval.policies import make_policy, parse_params
    from rich.table import Table

    if out_dir is not None:
        check_out_dir(out_dir)
    pairs = tuple(sorted(parse_params(params).items()))
    make_policy(policy, dict(pairs))  # a bad name or parameter stops here, in one line
    video = None if out_dir is None else str(out_dir / "episode.mp4")
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
    feed = None
    try:
        if view_port is not None:
            feed = open_view(
                scene_for(str(config))[0], f"{config} · {policy} · seed {seed}", view_port
            )
        result = run_episode(EpisodeSpec(str(config), seed, policy, pairs, steps, video), feed)
    finally:
        close_scenes()
    if out_dir is not None:
        line = json.dumps(asdict(result), sort_keys=True) + "\n"
        (out_dir / "episode.json").write_text(line)
    table = Table(title=f"sim run: {config}")
    for column in ("policy", "seed", "steps", "success", "sim time", "output"):
        table.add_column(column)
    table.add_row(
        policy,
        str(seed),
        str(result.steps),
        "yes" if result.success else "no",
        f"{result.sim_time_s:.2f} s",
        str(out_dir or "-"),
    )
    out.print(table, soft_wrap=False)
    if result.error is not None:
        out.print(f"the episode ended with an error: {result.error}", markup=False)
    if feed is not None:
        serve_until_interrupted(feed)
    if result.error is not None:
        raise typer.Exit(1)
