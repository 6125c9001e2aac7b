"""Pictures of every robot in its default scene, for the robot pages (``just docs-images``).

Each robot's ``scenes/tabletop.yaml`` is built with the native scene backend and reset with
the scene's seed; one frame is rendered offscreen (EGL on the CPU) from a free camera framed
as the scene's fixed cameras are (``openral_sim.camera_framing``): the whole robot and every
object near it inside the picture, from the view that sees most of them unhidden.

Next to the PNGs, ``renders.json`` records a SHA-256 of each picture's inputs (manifest,
scene file, MJCF file and the render settings) and the viewpoint used. :func:`stale_images`
compares it with the current inputs, which is cheap and needs no renderer.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from openral_codegen.models import CodegenError

if TYPE_CHECKING:
    import mujoco
    from openral_core.models import DeployScene, RobotDescription

IMAGE_DIR = "docs/images/robots"
RECORD_NAME = "renders.json"
DEFAULT_SCENE = "scenes/tabletop.yaml"
WIDTH, HEIGHT = 480, 360
"""Picture size [px]."""
SETTINGS: dict[str, Any] = {"size": [WIDTH, HEIGHT], "framing": "openral_sim.camera_framing"}


@dataclass(frozen=True)
class Render:
    """One rendered picture and the viewpoint it was taken from."""

    image: npt.NDArray[np.uint8]
    azimuth: float
    elevation: float


def render_robot(root: Path, robot_id: str) -> Render:
    """Render ``robot_id`` in its default scene (HEIGHT x WIDTH x 3, uint8)."""
    from openral_mujoco.display import use_offscreen_gl

    use_offscreen_gl()
    import mujoco
    from openral_core import open_robot_by_id
    from openral_core.loader import load_scene
    from openral_sim.scene import build_scene

    scene = load_scene(root / "robots" / robot_id / DEFAULT_SCENE)
    robot = open_robot_by_id(robot_id, root / "robots")
    env = build_scene(scene, robot)
    try:
        env.reset(seed=scene.seed)
        handles = env.mujoco_handles()
        if handles is None:
            raise CodegenError(f"{robot_id}: the default scene exposes no MuJoCo model")
        model, data = handles
        camera = _framing_camera(model, data, scene, robot.description)
        renderer = mujoco.Renderer(model, HEIGHT, WIDTH)
        try:
            renderer.update_scene(data, camera=camera)
            image = renderer.render().copy()
        finally:
            renderer.close()
    finally:
        env.close()
    return Render(image, float(camera.azimuth), float(camera.elevation))


def _framing_camera(
    model: mujoco.MjModel, data: mujoco.MjData, scene: DeployScene, robot: RobotDescription
) -> mujoco.MjvCamera:
    """A free camera framed as the scene's fixed cameras are (openral_sim.camera_framing:
    the whole robot and every object near it in the picture, from the view that sees most
    of them unhidden), for this picture's size and the model's free-camera field of view."""
    import mujoco
    from openral_sim.camera_framing import VIEWS, fit_view, framed_geoms, visible_share
    from openral_sim.scene_cameras import rotate_about_z

    names = [f"scene_{o.name}" for o in (scene.scene.options and scene.scene.options.objects) or []]
    framed = framed_geoms(model, data, robot, names)
    yaw = np.radians(scene.base_pose.yaw_deg or 0.0) if scene.base_pose else 0.0
    fovy = float(model.vis.global_.fovy)
    views = [
        fit_view(framed.points, rotate_about_z(float(yaw), np.array(v)), fovy, WIDTH / HEIGHT)
        for v in VIEWS
    ]
    eye, rotation = views[int(np.argmax([visible_share(model, data, framed, e) for e, _ in views]))]
    forward = -rotation[:, 2]
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.distance = 1.0
    camera.lookat[:] = eye + forward
    camera.azimuth = float(np.degrees(np.arctan2(forward[1], forward[0])))
    camera.elevation = float(np.degrees(np.arcsin(np.clip(forward[2], -1.0, 1.0))))
    return camera


def input_digest(root: Path, robot_id: str) -> str:
    """SHA-256 over everything a picture depends on, besides the scene code itself."""
    from openral_core.loader import load_robot
    from openral_mujoco.mjcf_uri import resolve_mjcf_uri

    folder = root / "robots" / robot_id
    manifest = folder / "robot.yaml"
    robot = load_robot(manifest)
    if robot.sim is None:
        raise CodegenError(f"{robot_id}: no sim block, so no picture can be rendered")
    digest = hashlib.sha256()
    for part in (
        manifest.read_bytes(),
        (folder / DEFAULT_SCENE).read_bytes(),
        resolve_mjcf_uri(robot.sim.mjcf_uri, folder).read_bytes(),
        json.dumps(SETTINGS, sort_keys=True).encode(),
    ):
        digest.update(hashlib.sha256(part).digest())
    return digest.hexdigest()


def write_images(root: Path, robot_ids: list[str] | None = None) -> list[str]:
    """Render the pictures of ``robot_ids`` (default: every robot); returns the paths written."""
    from openral_core.registry import robot_ids as all_robot_ids
    from openral_mujoco.png import write_png

    known = all_robot_ids(root / "robots")
    wanted = robot_ids or known
    unknown = sorted(set(wanted) - set(known))
    if unknown:
        raise CodegenError(f"unknown robot(s) {', '.join(unknown)}; known: {', '.join(known)}")
    folder = root / IMAGE_DIR
    folder.mkdir(parents=True, exist_ok=True)
    record = _read_record(root)
    written = []
    for robot_id in wanted:
        render = render_robot(root, robot_id)
        path = folder / f"{robot_id}.png"
        write_png(path, render.image)
        written.append(path.relative_to(root).as_posix())
        record[robot_id] = {
            "inputs_sha256": input_digest(root, robot_id),
            "azimuth_deg": render.azimuth,
            "elevation_deg": render.elevation,
        }
    for gone in set(record) - set(known):
        del record[gone]
        (folder / f"{gone}.png").unlink(missing_ok=True)
    (folder / RECORD_NAME).write_text(json.dumps(record, indent=2, sort_keys=True) + "\n")
    return written


def stale_images(root: Path) -> list[str]:
    """Robots whose picture is missing or was rendered from other inputs, with the reason."""
    from openral_core.registry import robot_ids

    record = _read_record(root)
    problems = []
    for robot_id in robot_ids(root / "robots"):
        if not (root / IMAGE_DIR / f"{robot_id}.png").is_file():
            problems.append(f"{robot_id}: no picture")
        elif record.get(robot_id, {}).get("inputs_sha256") != input_digest(root, robot_id):
            problems.append(f"{robot_id}: manifest, scene, model or settings changed")
    known = set(robot_ids(root / "robots"))
    gone = sorted(set(record) - known)
    problems += [f"{robot_id}: picture of a robot that no longer exists" for robot_id in gone]
    return sorted(problems)


def _read_record(root: Path) -> dict[str, dict[str, Any]]:
    path = root / IMAGE_DIR / RECORD_NAME
    if not path.is_file():
        return {}
    record: dict[str, dict[str, Any]] = json.loads(path.read_text("utf-8"))
    return record
