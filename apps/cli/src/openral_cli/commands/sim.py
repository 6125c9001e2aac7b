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
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from openral_cli.browser_view import DEFAULT_VIEW_PORT, View, ViewPort
from openral_cli.commands.policies import policies
from openral_cli.commands.sim_bus import bus
from openral_cli.commands.sim_export import sim_export
from openral_cli.commands.sim_policy import run_policy
from openral_cli.commands.sim_replay import replay
from openral_cli.commands.sweep import sweep
from openral_cli.console import out, progress
from openral_cli.help_text import PARAM_HELP, command_group

if TYPE_CHECKING:
    from openral_hal.protocol import ObservingHal, RobotHal
    from openral_hal.view_feed import ViewFeed

app = command_group("Run simulated scenes, or sweep a policy over scenes and seeds.")
app.command("sweep")(sweep)
app.command("policies")(policies)
app.command("replay")(replay)
app.command("export")(sim_export)
app.command("bus")(bus)

SWAY_RAD = 0.15
"""Amplitude of the demo motion around the start pose."""
MOTIONS = ("sway", "hold")
DEFAULT_STEPS = 50
"""Steps of a ``--motion`` run."""


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
    steps: Annotated[
        int | None,
        typer.Option(
            "--steps", min=1, help="Control steps (default: 50; with --policy, an episode's)."
        ),
    ] = None,
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
    policy: Annotated[
        str | None,
        typer.Option("--policy", help="Run one episode of this policy (name or file.py:Class)."),
    ] = None,
    params: Annotated[list[str] | None, typer.Option("--param", "-p", help=PARAM_HELP)] = None,
    seed: Annotated[int, typer.Option("--seed", help="The episode's seed (with --policy).")] = 0,
    view: View = False,
    view_port: ViewPort = DEFAULT_VIEW_PORT,
) -> None:
    """Run SCENE headless for N control steps; save every camera frame and joint state.

    The scene is driven exactly as ``openral deploy sim`` drives it: through the
    SimAttachedHAL that ``build_hal`` attaches, from the hold action of its backend. The
    scene file and the robot's manifest are each read once. With ``--policy``, one episode
    of that policy runs instead, exactly as ``sim sweep`` runs it (``--seed``).
    """
    if policy is not None:
        if robot is not None or manifest is not None:
            raise typer.BadParameter(
                "--policy runs the scene's own robot, as a sweep does; drop --robot/--manifest",
                param_hint="--policy",
            )
        run_policy(config, policy, params or [], seed, steps, out_dir, view_port if view else None)
        return
    who = (robot, manifest)
    _run_motion(config, steps or DEFAULT_STEPS, out_dir, who, motion, view_port if view else None)


def _run_motion(
    config: Path,
    steps: int,
    out_dir: Path | None,
    who: tuple[str | None, Path | None],
    motion: str,
    view_port: int | None = None,
) -> None:
    """The ``--motion`` run: the scene's robot (or ``who``: a robot id, a manifest) swaying
    or holding for ``steps`` steps, every frame and joint state recorded; with a
    ``view_port``, drawn in the browser view, which stays up after the run."""
    from openral_core import open_robot
    from openral_core.loader import load_scene
    from openral_hal.factory import HalMode, build_hal
    from openral_sim.scene import build_scene, check_scene_robot, scene_robot
    from rich.table import Table

    from openral_cli.browser_view import open_view, serve_until_interrupted

    robot, manifest = who
    if motion not in MOTIONS:
        raise typer.BadParameter("expected 'sway' or 'hold'", param_hint="--motion")
    scene = load_scene(config)
    if manifest is not None:
        loaded = open_robot(manifest)
        check_scene_robot(scene, loaded)
    else:
        loaded = scene_robot(scene, robot)
    every_step = partial(build_scene, frame_rate_hz=math.inf)  # a frame of each camera per step
    hal = build_hal(loaded, mode=HalMode.SIM, scene=scene, env_builder=every_step)
    hal.connect()
    feed = None
    try:
        if view_port is not None:
            feed = open_view(hal, f"{scene.scene.id} · {loaded.name}", view_port)
        if out_dir:
            out_dir.mkdir(parents=True, exist_ok=True)
        with progress() as bar:
            task = bar.add_task(f"{scene.scene.id} · {loaded.name}", total=steps)
            seen = _drive(hal, steps, motion, out_dir, lambda: bar.advance(task), feed)
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
    if feed is not None:
        serve_until_interrupted(feed)


def _drive(
    hal: RobotHal,
    steps: int,
    motion: str,
    out_dir: Path | None,
    advance: Callable[[], None],
    feed: ViewFeed | None = None,
) -> Recording:
    """Step a connected HAL from its hold action, recording joints (manifest names) and the
    sensor frames of each step's observation (files in ``out_dir``), each step shown in
    the view when there is a ``feed``."""
    from openral_hal.protocol import ObservingHal

    hold = hal.hold_action()
    seen = Recording()
    for step in range(steps):
        phase = math.sin(2 * math.pi * step / max(steps, 20))
        action = hold + (SWAY_RAD * phase if motion == "sway" else 0.0)
        hal.send_action(action)
        if feed is not None:
            feed(dict(zip(hal.action_names, action.tolist(), strict=True)))
        state = hal.read_state()
        positions = zip(state.names, state.positions.tolist(), strict=True)
        seen.records.append({"step": step, "time": state.sim_time_s, "positions": dict(positions)})
        if isinstance(hal, ObservingHal):
            _record_frames(hal, seen, out_dir, step)
        advance()
    return seen


def _record_frames(hal: ObservingHal, seen: Recording, out_dir: Path | None, step: int) -> None:
    """Write the camera, depth and lidar frames of the HAL's last observation to ``out_dir``
    (see the module doc) and note which sensors gave them."""
    import numpy as np
    from openral_hal.protocol import LidarSource
    from openral_mujoco.png import encode_depth_png, write_png

    obs = hal.last_observation()
    seen.cameras = list(dict.fromkeys([*seen.cameras, *obs.images]))
    seen.depth = list(dict.fromkeys([*seen.depth, *obs.depth]))
    seen.lidars = list(dict.fromkeys([*seen.lidars, *obs.scans]))
    if not out_dir:
        return
    for camera, image in obs.images.items():
        write_png(out_dir / f"{camera}_{step:04d}.png", image)
    for name, frame in obs.depth.items():
        (out_dir / f"{name}_{step:04d}.depth.png").write_bytes(encode_depth_png(frame.depth_m))
        np.save(out_dir / f"{name}_{step:04d}.points.npy", frame.points)
    lidars = hal.lidar_sensors() if isinstance(hal, LidarSource) else {}
    for name, scan in obs.scans.items():
        spec = lidars[name]
        count = len(scan.ranges)
        increment = (spec.angle_max_rad - spec.angle_min_rad) / (count - 1) if count > 1 else 0.0
        line: dict[str, object] = {"step": step, "time": scan.sim_time_s}
        line |= {"angle_min": spec.angle_min_rad, "angle_increment": increment}
        line["ranges"] = [r if math.isfinite(r) else str(r) for r in scan.ranges.tolist()]
        with (out_dir / f"{name}.scan.jsonl").open("w" if step == 0 else "a") as scans:
            scans.write(json.dumps(line) + "\n")
