"""``openral sim``: run a deploy-scene headless and record what its cameras and joints see.

Example::

    openral sim run --config robots/franka_panda/scenes/tabletop.yaml --steps 50 --out o/
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import mujoco
import numpy as np
import typer
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

app = typer.Typer(help="Run simulated scenes.", no_args_is_help=True)
out = Console()

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
    """Run SCENE headless for N control steps; save every camera frame and joint state."""
    from openral_core.loader import load_scene
    from openral_core.registry import load_robot_by_id
    from openral_sim.png import write_png
    from openral_sim.scene import build_sim_env_from_yaml

    if motion not in ("sway", "hold"):
        raise typer.BadParameter("expected 'sway' or 'hold'", param_hint="--motion")
    scene = load_scene(config)
    robot_id = scene.robot_id or robot
    env = build_sim_env_from_yaml(config, robot_id_fallback=robot)
    description = load_robot_by_id(robot_id or "")
    joint_names = [j.sim_joint_name or j.name for j in description.joints]
    records: list[dict[str, object]] = []
    try:
        obs = env.reset(scene.seed)
        handles = env.mujoco_handles()
        hold = np.array(handles[1].ctrl) if handles else np.zeros(env.action_dim or 0)
        addresses = _joint_addresses(handles, joint_names)
        if out_dir:
            out_dir.mkdir(parents=True, exist_ok=True)
        with Progress(console=out, transient=True) as progress:
            task = progress.add_task(f"{scene.scene.id} · {robot_id}", total=steps)
            for step in range(steps):
                phase = math.sin(2 * math.pi * step / max(steps, 20))
                action = hold + (SWAY_RAD * phase if motion == "sway" else 0.0)
                obs = env.step(action).obs
                records.append(_joint_record(step, handles, addresses))
                if out_dir:
                    for camera, image in obs["images"].items():
                        write_png(out_dir / f"{camera}_{step:04d}.png", image)
                progress.advance(task)
    finally:
        env.close()
    if out_dir:
        (out_dir / "joint_states.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    table = Table(title=f"sim run: {config}")
    for column in ("robot", "backend", "steps", "cameras", "output"):
        table.add_column(column)
    table.add_row(
        str(robot_id),
        scene.scene.backend.value,
        str(steps),
        ", ".join(obs["images"]),
        str(out_dir or "-"),
    )
    out.print(table)


def _joint_addresses(
    handles: tuple[mujoco.MjModel, mujoco.MjData] | None, joint_names: list[str]
) -> dict[str, int]:
    """qpos address of every manifest (MJCF) joint name present in the scene's model."""
    if handles is None:
        return {}
    model = handles[0]
    ids = {name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in joint_names}
    return {name: int(model.jnt_qposadr[jid]) for name, jid in ids.items() if jid >= 0}


def _joint_record(
    step: int, handles: tuple[mujoco.MjModel, mujoco.MjData] | None, addresses: dict[str, int]
) -> dict[str, object]:
    """Joint positions by manifest (MJCF) name at one step."""
    record: dict[str, object] = {"step": step}
    if handles is None:
        return record
    data = handles[1]
    record["time"] = float(data.time)
    record["positions"] = {name: float(data.qpos[addr]) for name, addr in addresses.items()}
    return record
