"""The TCP as MuJoCo sensors of a native scene: a site at the TCP (``openral_tcp``, in a
site group no camera draws) and its position and orientation (``openral_tcp_pos``,
``openral_tcp_quat``) in the frame of the robot's root body (MuJoCo's ``xbody``: the body's
own frame, not its inertial one). MuJoCo computes them with the rest of the state, in C;
:class:`~openral_sim.tcp_pose.TcpReader` reads them.
"""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core.models import RobotDescription
from openral_core.tables import joint_name_map
from openral_core.tcp_wiring import tcp_wiring

TCP_SITE = "openral_tcp"
TCP_SENSORS = ("openral_tcp_pos", "openral_tcp_quat")
"""The TCP's position [m] and quaternion (w, x, y, z) in the root body, in ``sensordata``."""
HIDDEN_SITE_GROUP = 5
"""A site group MuJoCo's default visual options do not draw (they draw groups 0-2)."""


def add_tcp_sensors(spec: mujoco.MjSpec, robot: RobotDescription, alone: mujoco.MjModel) -> None:
    """Add the TCP site and its two sensors to a scene ``spec`` holding ``robot`` (attached
    with its own names; ``alone``: the robot's model by itself, where a TCP site's pose in
    its body is read). Nothing without a TCP."""
    tcp = tcp_wiring(robot.sim.tcp) if robot.sim is not None else None
    if tcp is None:
        return
    offset, quat = np.array(tcp.offset_m), np.array(tcp.quat_wxyz)
    body_name = tcp.frame
    if tcp.kind == "site":  # the TCP's pose in the site's body, from the compiled robot
        site = mujoco.mj_name2id(alone, mujoco.mjtObj.mjOBJ_SITE, tcp.frame)
        body_name = mujoco.mj_id2name(alone, mujoco.mjtObj.mjOBJ_BODY, alone.site_bodyid[site])
        at, at_quat = np.empty(3), np.empty(4)
        mujoco.mju_mulPose(at, at_quat, alone.site_pos[site], alone.site_quat[site], offset, quat)
        offset, quat = at, at_quat
    body, root = spec.body(body_name), _root_body(spec, robot)
    if body is None or root is None:  # the model check names what is missing
        return
    body.add_site(name=TCP_SITE, pos=offset.tolist(), quat=quat.tolist(), group=HIDDEN_SITE_GROUP)
    for name, kind in zip(
        TCP_SENSORS,
        (mujoco.mjtSensor.mjSENS_FRAMEPOS, mujoco.mjtSensor.mjSENS_FRAMEQUAT),
        strict=True,
    ):
        spec.add_sensor(
            name=name,
            type=kind,
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=TCP_SITE,
            reftype=mujoco.mjtObj.mjOBJ_XBODY,
            refname=root,
        )


def _root_body(spec: mujoco.MjSpec, robot: RobotDescription) -> str | None:
    """The world's child that carries the robot's first manifest joint (the root body
    :func:`~openral_mujoco.robot_bodies.root_body` finds in the compiled model)."""
    joint = spec.joint(next(iter(joint_name_map(robot).values())))
    if joint is None:
        return None
    body = joint.parent
    while body.parent is not None and body.parent.name != spec.worldbody.name:
        body = body.parent
    return str(body.name)
