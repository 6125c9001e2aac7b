"""``openral sim``: run a deploy-scene headless and record what its cameras and joints see.

Example::

    openral sim run --config robots/franka_panda/scenes/tabletop.yaml --steps 50 --out o/

``joint_states.jsonl`` holds one line per step: ``{"step", "time", "positions"}`` with the
positions keyed by the manifest's joint names, as ``/joint_states`` names them. Each step
also writes every camera's frame (``<sensor>_<step>.png``) and, on a native scene, every
depth sensor's image (``<sensor>_<step>.depth.png``, 16-bit, millimetres, 0 = no reading)
and self-filtered cloud (``<sensor>_<step>.points.npy``, N x 3 float32 in the robot's base
frame, metres), and one line per step of every lidar's scan to ``<sensor>.scan.jsonl``:
``{"step", "time", "angle_min", "angle_increment", "ranges"}`` (radians, metres; REP 117's
infinities as the strings ``"inf"`` and ``"-inf"``, which ``float()`` reads back).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from openral_cli.commands.sweep import sweep
from openral_cli.console import out, progress
from openral_cli.help_text import command_group

if TYPE_CHECKING:
    from openral_hal.protocol import RobotHal

app = command_group("Run simulated scenes, or sweep a policy over scenes and seeds.")
app.command("sweep")(sweep)

SWAY_RAD = 0.15
"""Amplitude of the demo motion around the start pose."""
MOTIONS = ("sway", "hold")


@dataclass
class Recording:
    """What a run saw: one joint-state record per step and the cameras that rendered."""

    records: list[dict[str, object]] = field(default_factory=list)
    cameras: list[str] = field(default_factory=list)
    depth: list[str] = field(default_factory=list)
    lidars: list[str] = field(default_factory=list)


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
    manifest: Annotated[
        Path | None, typer.Option("--manifest", help="Manifest file (default: the scene's robot).")
    ] = None,
    motion: Annotated[
        str, typer.Option("--motion", help="'sway' (a slow joint-space sine) or 'hold'.")
    ] = "sway",
) -> None:
    """Run SCENE headless for N control steps; save every camera frame and joint state.

    The scene is driven exactly as ``openral deploy sim`` drives it: through the
    SimAttachedHAL that ``build_hal`` attaches, from the hold action of its backend. The
    scene file and the robot's manifest are each read once.
    """
    from openral_core import open_robot
    from openral_core.loader import load_scene
    from openral_hal.factory import HalMode, build_hal
    from openral_sim.scene import check_scene_robot, scene_robot
    from rich.table import Table

    if motion not in MOTIONS:
        raise typer.BadParameter("expected 'sway' or 'hold'", param_hint="--motion")
    scene = load_scene(config)
    if manifest is not None:
        loaded = open_robot(manifest)
        check_scene_robot(scene, loaded)
    else:
        loaded = scene_robot(scene, robot)
    hal = build_hal(loaded, mode=HalMode.SIM, scene=scene)
    hal.connect()
    try:
        if out_dir:
            out_dir.mkdir(parents=True, exist_ok=True)
        with progress() as bar:
            task = bar.add_task(f"{scene.scene.id} · {loaded.name}", total=steps)
            seen = _drive(hal, steps, motion, out_dir, lambda: bar.advance(task))
    finally:
        hal.disconnect()
    if out_dir:
        lines = "".join(json.dumps(record) + "\n" for record in seen.records)
        (out_dir / "joint_states.jsonl").write_text(lines)
    table = Table(title=f"sim run: {config}")
    for column in ("robot", "backend", "steps", "cameras", "depth", "lidars", "output"):
        table.add_column(column)
    sensors = [", ".join(names) or "-" for names in (seen.cameras, seen.depth, seen.lidars)]
    backend = scene.scene.backend.value
    table.add_row(loaded.name, backend, str(steps), *sensors, str(out_dir or "-"))
    out.print(table, soft_wrap=False)  # centred title, as this command always printed it


def _drive(
    hal: RobotHal,
    steps: int,
    motion: str,
    out_dir: Path | None,
    advance: Callable[[], None],
) -> Recording:
    """Step a connected HAL from its hold action, recording joints (manifest names) and
    camera frames (PNG files in ``out_dir``)."""
    from openral_hal.protocol import CameraHal
    from openral_mujoco.png import write_png

    hold = hal.hold_action()
    seen = Recording()
    for step in range(steps):
        phase = math.sin(2 * math.pi * step / max(steps, 20))
        hal.send_action(hold + (SWAY_RAD * phase if motion == "sway" else 0.0))
        state = hal.read_state()
        positions = zip(state.names, state.positions.tolist(), strict=True)
        seen.records.append({"step": step, "time": state.sim_time_s, "positions": dict(positions)})
        images = hal.read_images() if isinstance(hal, CameraHal) else {}
        seen.cameras = list(images)
        if out_dir:
            for camera, image in images.items():
                write_png(out_dir / f"{camera}_{step:04d}.png", image)
        seen.depth, seen.lidars = _record_range(hal, out_dir, step, state.sim_time_s)
        advance()
    return seen


def _record_range(
    hal: RobotHal, out_dir: Path | None, step: int, time: float | None
) -> tuple[list[str], list[str]]:
    """Write each depth sensor's image and cloud and each lidar's scan of a native scene to
    ``out_dir`` (see the module doc); the depth sensors' and the lidars' names."""
    import numpy as np
    from openral_hal.sim_attached import native_scene
    from openral_mujoco.png import encode_depth_png

    scene = native_scene(hal)
    if scene is None:
        return [], []
    sensors = scene.range_sensors
    if out_dir:
        for name in sensors.depth:
            frame = sensors.depth_frame(name, scene.data)
            depth_png = encode_depth_png(frame.depth_m)
            (out_dir / f"{name}_{step:04d}.depth.png").write_bytes(depth_png)
            np.save(out_dir / f"{name}_{step:04d}.points.npy", frame.points)
        for name, scanner in sensors.lidars.items():
            ranges = [
                r if math.isfinite(r) else str(r) for r in sensors.scan(name, scene.data).tolist()
            ]
            line: dict[str, object] = {"step": step, "time": time}
            line |= {"angle_min": scanner.angle_min, "angle_increment": scanner.angle_increment}
            line["ranges"] = ranges
            with (out_dir / f"{name}.scan.jsonl").open("w" if step == 0 else "a") as scans:
                scans.write(json.dumps(line) + "\n")
    return list(sensors.depth), list(sensors.lidars)
