"""Where a native scene's fixed cameras stand: in front of the robot, above and to one side,
as close as they can be with the whole robot and every object around it in the picture.

A fixed camera is a camera sensor with neither ``camera`` nor ``mount_body``. What it shows
is the robot in its start pose (the bounding box of each of its visible geoms) and every
object near it: each body of the scene's ``objects`` and each loose body of the robot's
file (a cube the model brings), loose or fixed, whose geoms' boxes lie within
:data:`WORK_RANGE_M` of the robot's box. A wall, or a probe parked across the room, is
left out.

For each of the :data:`VIEWS` (directions in the frame of the scene's base pose), with the
sensor's vertical field of view at the scene's image size (a depth sensor's own), the
closest camera position that has every corner of those boxes at least
:data:`FRAME_MARGIN` of the half-image inside its edges is found in closed form
(:func:`fit_view`). Of these, the camera takes the first that sees the most of the robot
and the objects unhidden (:func:`visible_share`, by ray casting: a robot whose model
brings a second arm in front of it is seen from the side). Cameras are placed after the
scene is compiled, in the start pose a reset gives before its settle steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import DeployScene, DepthSensor, RgbSensor, RobotDescription
from openral_mujoco.robot_bodies import robot_bodies

from openral_sim.scene_cameras import rotate_about_z
from openral_sim.scene_geometry import geom_corners, start_pose

VIEWS = ((1.0, 0.3, 0.55), (1.0, -0.3, 0.55), (0.3, 1.0, 0.55), (0.3, -1.0, 0.55))
"""Directions from what the camera shows towards the camera, in the base pose's frame, in
order of preference: in front of the robot (+x) and a little to its left, about 29 degrees
above the horizon; then front right, then from either side."""
FRAME_MARGIN = 0.08
"""Part of each half-image (centre to edge) kept free at every edge."""
WORK_RANGE_M = 1.0
"""An object is framed when its box lies within this distance of the robot's box [m]."""
NEAR_M = 0.1
"""Least distance [m] in front of the camera of anything it frames."""
VISIBLE_GROUPS = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8)
"""Geom groups a camera draws by default."""


@dataclass(frozen=True)
class Framed:
    """What a fixed camera must show: geoms of the robot and of the objects near it."""

    robot: npt.NDArray[np.int_]
    objects: npt.NDArray[np.int_]
    points: npt.NDArray[np.float64]
    """Corners of the boxes of all of them, in the world frame."""


def place_fixed_cameras(
    model: mujoco.MjModel, scene: DeployScene, robot: RobotDescription, cameras: dict[str, str]
) -> None:
    """Set the pose (``cam_pos``, ``cam_quat``) of each fixed camera of ``cameras`` (sensor
    name -> MJCF camera) in the compiled scene ``model``, as the module doc says."""
    fixed = [
        s
        for s in robot.sensors
        if isinstance(s, RgbSensor | DepthSensor)
        and s.name in cameras
        and s.camera is None
        and s.mount_body is None
    ]
    if not fixed:
        return
    data = start_pose(model, robot, scene.base_pose)
    names = [f"scene_{o.name}" for o in (scene.scene.options and scene.scene.options.objects) or []]
    framed = framed_geoms(model, data, robot, names)
    pose = scene.base_pose
    yaw = math.radians(pose.yaw_deg if pose and pose.yaw_deg else 0.0)
    observation = scene.scene.observation
    for sensor in fixed:
        size = (sensor.width, sensor.height) if isinstance(sensor, DepthSensor) else None
        width, height = size or (observation.width, observation.height)
        camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, cameras[sensor.name])
        fovy = float(model.cam_fovy[camera])
        views = [
            fit_view(framed.points, rotate_about_z(yaw, np.array(v)), fovy, width / height)
            for v in VIEWS
        ]
        scores = [visible_share(model, data, framed, eye) for eye, _ in views]
        eye, rotation = views[int(np.argmax(scores))]
        model.cam_pos[camera] = eye
        mujoco.mju_mat2Quat(model.cam_quat[camera], rotation.ravel())


def framed_geoms(
    model: mujoco.MjModel, data: mujoco.MjData, robot: RobotDescription, objects: list[str]
) -> Framed:
    """The geoms a fixed camera must show (see the module doc), as ``data`` poses them;
    ``objects`` are the body names of the scene's objects."""
    visible = (model.geom_group < 3) & (model.geom_rgba[:, 3] > 0)
    on_robot = np.isin(model.geom_bodyid, list(robot_bodies(model, robot)))
    robot_geoms = np.flatnonzero(visible & on_robot)
    robot_points = geom_corners(model, data, robot_geoms)
    low = robot_points.min(axis=0) - WORK_RANGE_M
    high = robot_points.max(axis=0) + WORK_RANGE_M
    points, object_geoms = [robot_points], []
    for body in range(1, model.nbody):
        named = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) in objects
        loose = model.body_weldid[body] != 0
        geoms = np.flatnonzero(visible & ~on_robot & (model.geom_bodyid == body))
        if not len(geoms) or not (named or loose):
            continue
        corners = geom_corners(model, data, geoms)
        if ((corners >= low) & (corners <= high)).all():
            points.append(corners)
            object_geoms.extend(geoms.tolist())
    return Framed(robot_geoms, np.array(object_geoms, dtype=int), np.concatenate(points))


def visible_share(
    model: mujoco.MjModel, data: mujoco.MjData, framed: Framed, eye: npt.NDArray[np.float64]
) -> float:
    """How much of ``framed`` a camera at ``eye`` sees unhidden: the share of robot geoms,
    plus the share of object geoms, whose box centre the ray from ``eye`` reaches first
    (a robot geom may be hidden by another of the robot's, an object's only by itself)."""
    geoms = np.concatenate([framed.robot, framed.objects])
    centres = data.geom_xpos[geoms] + np.einsum(
        "gij,gj->gi", data.geom_xmat[geoms].reshape(-1, 3, 3), model.geom_aabb[geoms, :3]
    )
    rays = centres - eye
    hit = np.full(len(geoms), -1, dtype=np.int32)
    distance = np.zeros(len(geoms))
    mujoco.mj_multiRay(
        model,
        data,
        eye,
        rays.ravel(),
        VISIBLE_GROUPS,
        True,
        -1,
        hit,
        distance,
        None,
        len(geoms),
        1e3,
    )
    owner = np.where(hit >= 0, model.geom_bodyid[hit], -1)
    robot = len(framed.robot)
    seen_robot = np.isin(owner[:robot], model.geom_bodyid[framed.robot])
    seen_objects = owner[robot:] == model.geom_bodyid[framed.objects]
    return float(seen_robot.mean() + (seen_objects.mean() if len(seen_objects) else 0.0))


def fit_view(
    points: npt.NDArray[np.float64],
    direction: npt.NDArray[np.float64],
    fovy_deg: float,
    aspect: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The closest camera looking along ``-direction`` (image up towards world +z) that has
    every one of ``points`` inside its picture, :data:`FRAME_MARGIN` from the edges.

    With the view direction fixed, a point (x, y) across and s along it from any centre is
    inside when |x - a| <= t (d - s) for the camera's offsets a across and d back, t the
    tangent of the half field of view; the least d for which some a satisfies every point
    is ``(max(s + x / t) + max(s - x / t)) / 2``, the same for y, and a is then the middle
    of the interval left.

    Returns:
        The camera's position and its rotation (columns: image right, image up, backwards
        along the view; a MuJoCo camera looks along its -z).
    """
    back = direction / np.linalg.norm(direction)
    right = np.cross(-back, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, -back)
    centre = (points.min(axis=0) + points.max(axis=0)) / 2
    relative = points - centre
    along, across, rise = relative @ back, relative @ right, relative @ up
    tan_y = math.tan(math.radians(fovy_deg) / 2) * (1 - FRAME_MARGIN)
    tan_x = tan_y * aspect
    distance = max(
        _least_distance(across, along, tan_x),
        _least_distance(rise, along, tan_y),
        float(along.max()) + NEAR_M,
    )
    offset = _centred_offset(across, along, tan_x, distance) * right
    offset += _centred_offset(rise, along, tan_y, distance) * up
    eye = centre + distance * back + offset
    return eye, np.column_stack([right, up, back])


def _least_distance(
    coordinate: npt.NDArray[np.float64], along: npt.NDArray[np.float64], tangent: float
) -> float:
    return float((np.max(along + coordinate / tangent) + np.max(along - coordinate / tangent)) / 2)


def _centred_offset(
    coordinate: npt.NDArray[np.float64],
    along: npt.NDArray[np.float64],
    tangent: float,
    distance: float,
) -> float:
    depth = distance - along
    return float((np.max(coordinate - tangent * depth) + np.min(coordinate + tangent * depth)) / 2)
