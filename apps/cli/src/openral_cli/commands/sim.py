"""``openral sim``: run a deploy-scene headless and record what its cameras and joints see.

Example::

    openral sim run --config robots/franka_panda/scenes/tabletop.yaml --steps 50 --out o/
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer
from openral_core.tables import joint_name_map
from rich.table import Table

from openral_cli.console import out, progress

app = typer.Typer(help="Run simulated scenes.", no_args_is_help=True)

SWAY_RAD = 0.15
"""Amplitude of the demo motion around the start pose."""


@app.command("run")
def run(
    config: Annotated[Path, typer.Option("--config", help="Deploy-scene YAML file.")],
    steps: Annotated[int, typer.Option("--steps", min=1, help="Control steps to run.")] = 50,
    out_dir: Annotated[
        Path | None, typer.Option("--out", help="Write PNG frames and joint states here.")
    ] = None,
    robot: Annotated[
        str | None, typer.Option("--robot", help="Robot id when the scene names none.")
    ] = None,
    motion: Annotated[
        str, typer.Option("--motion", help="'sway' (a slow joint-space sine) or 'hold'.")
    ] = "sway",
) -> None:
    """Run SCENE headless for N control steps; save every camera frame and joint state.

    The scene is driven exactly as ``openral deploy sim`` drives it: through the
    SimAttachedHAL that ``build_hal`` attaches, from the hold action of its backend.
    """
    from openral_core.errors import OpenralError
    from openral_core.loader import load_scene
    from openral_core.registry import load_robot_by_id
    from openral_hal.factory import build_hal

    if motion not in ("sway", "hold"):
        raise typer.BadParameter("expected 'sway' or 'hold'", param_hint="--motion")
    scene = load_scene(config)
    robot_id = scene.robot_id or robot
    if robot_id is None:
        raise OpenralError(f"{config}: robot_id: the scene names no robot and none was given")
    description = load_robot_by_id(robot_id)
    hal = build_hal(description, mode="sim", sim_env_yaml=config)
    hal.connect()
    try:
        if out_dir:
            out_dir.mkdir(parents=True, exist_ok=True)
        with progress() as bar:
            task = bar.add_task(f"{scene.scene.id} · {robot_id}", total=steps)
            records, cameras = _drive(
                hal, joint_name_map(description), steps, motion, out_dir, lambda: bar.advance(task)
            )
    finally:
        hal.disconnect()
    if out_dir:
        (out_dir / "joint_states.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    table = Table(title=f"sim run: {config}")
    for column in ("robot", "backend", "steps", "cameras", "output"):
        table.add_column(column)
    table.add_row(
        robot_id, scene.scene.backend.value, str(steps), ", ".join(cameras), str(out_dir or "-")
    )
    out.print(table, soft_wrap=False)  # centred title, as this command always printed it


def _drive(
    hal: Any,
    mjcf_name: dict[str, str],
    steps: int,
    motion: str,
    out_dir: Path | None,
    advance: Callable[[], None],
) -> tuple[list[dict[str, object]], list[str]]:
    """Step a connected HAL from its hold action; the joint records and the camera names."""
    from openral_mujoco.png import write_png

    hold = hal.hold_action()
    records: list[dict[str, object]] = []
    cameras: list[str] = []
    for step in range(steps):
        phase = math.sin(2 * math.pi * step / max(steps, 20))
        hal.send_action(hold + (SWAY_RAD * phase if motion == "sway" else 0.0))
        state = hal.read_state()
        positions = zip(state.names, state.positions, strict=True)
        records.append(
            {
                "step": step,
                "time": state.sim_time_s,
                "positions": {mjcf_name[name]: float(value) for name, value in positions},
            }
        )
        images = hal.read_images()
        cameras = list(images)
        if out_dir:
            for camera, image in images.items():
                write_png(out_dir / f"{camera}_{step:04d}.png", image)
        advance()
    return records, cameras
