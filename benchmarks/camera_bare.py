"""The baseline of ``bench-camera``: the scene ``deploy sim`` runs, as a bare MuJoCo loop.

No ROS and no HAL: the deploy scene is composed through the public API
(:func:`openral_sim.scene.build_scene` of the loaded scene and robot) and reset as ``deploy
sim``'s connect resets it; then one loop, in wall-clock real time, steps the model one
control period (``mj_step`` of the scene's physics steps per control tick) at the scene's
control rate and renders every camera of the scene with one :class:`mujoco.Renderer` at the
scene's image size and the given camera rate, sleeping between ticks. A late tick is not
made up, as ``deploy sim``'s timers do not make one up.

Run by ``benchmarks.camera_path`` as ``python -m benchmarks.camera_bare --scene FILE
--camera-rate HZ``: it prints ``ready`` once the first frames are rendered, runs until
SIGINT or SIGTERM, then prints its counts as one JSON line.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import mujoco
from openral_core.loader import load_scene
from openral_sim.scene import build_scene, scene_robot


@dataclass
class Counts:
    """What the loop did: control ticks, frames rendered (all cameras) and its wall time [s]."""

    ticks: int = 0
    frames: int = 0
    wall_s: float = 0.0


def next_due(due: float, period: float, now: float) -> float:
    """The next time a periodic tick due at ``due`` runs again: one ``period`` later, or the
    first multiple of ``period`` after ``now`` when the tick ran late (missed ticks are
    skipped, never made up) [s, the clock of ``now``]."""
    following = due + period
    if following > now:
        return following
    return following + period * (math.floor((now - following) / period) + 1)


@dataclass(frozen=True)
class BareScene:
    """The composed model and what the loop needs to run it as ``deploy sim`` does."""

    model: mujoco.MjModel
    data: mujoco.MjData
    substeps: int
    """Physics steps per control tick."""
    control_period_s: float
    cameras: tuple[str, ...]
    """MJCF cameras of the scene's camera sensors."""
    size: tuple[int, int]
    """(height, width) of a frame [px]."""


def bare_scene(path: Path) -> BareScene:
    """Load ``path`` and its robot, build the scene, reset it (as connect does)."""
    scene = load_scene(path)
    rollout = build_scene(scene, scene_robot(scene))
    rollout.reset()
    handles = rollout.mujoco_handles()
    if handles is None:
        raise SystemExit(f"{path}: the {scene.scene.backend.value} backend has no MuJoCo model")
    model, data = handles
    period = rollout.control_period_s
    observation = scene.scene.observation
    return BareScene(
        model=model,
        data=data,
        substeps=max(1, round(period / model.opt.timestep)),
        control_period_s=period,
        cameras=tuple(rollout.camera_models.values()),
        size=(observation.height, observation.width),
    )


def render_all(renderer: mujoco.Renderer, scene: BareScene) -> int:
    """Render every camera once; the number of frames."""
    for camera in scene.cameras:
        renderer.update_scene(scene.data, camera=camera)
        renderer.render()
    return len(scene.cameras)


def run(
    scene: BareScene, renderer: mujoco.Renderer, camera_period_s: float, stop: threading.Event
) -> Counts:
    """Step and render in real time until ``stop`` is set."""
    counts = Counts()
    start = time.monotonic()
    control_due = camera_due = start
    while not stop.is_set():
        now = time.monotonic()
        if now >= control_due:
            mujoco.mj_step(scene.model, scene.data, nstep=scene.substeps)
            counts.ticks += 1
            control_due = next_due(control_due, scene.control_period_s, time.monotonic())
        if now >= camera_due:
            counts.frames += render_all(renderer, scene)
            camera_due = next_due(camera_due, camera_period_s, time.monotonic())
        stop.wait(max(0.0, min(control_due, camera_due) - time.monotonic()))
    counts.wall_s = time.monotonic() - start
    return counts


def main() -> int:
    """Build, announce ``ready``, loop until a signal, print the counts."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scene", type=Path, required=True, help="deploy-scene file")
    parser.add_argument("--camera-rate", type=float, required=True, help="camera rate [Hz]")
    args = parser.parse_args()
    scene = bare_scene(args.scene)
    height, width = scene.size
    renderer = mujoco.Renderer(scene.model, height, width)
    render_all(renderer, scene)
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    print("ready", flush=True)
    counts = run(scene, renderer, 1.0 / args.camera_rate, stop)
    renderer.close()
    print(json.dumps(asdict(counts)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
