"""The one observation: the keys that the scene env, a policy and a dataset row share.

Every path that shows a robot to a learner (the gymnasium env, a sweep's episode, ``rskill
run`` on a ROS graph, a policy server, a LeRobot dataset) names what it shows by these
keys, LeRobot's where LeRobot has one, in one flat mapping (no nesting; each image once):

====================================  ============================================  ==========
key                                   value                                         units
====================================  ============================================  ==========
``observation.state``                 joint positions, every manifest joint, in     rad, m
                                      manifest order (grippers per their read mode)
``observation.velocity``              the same joints' velocities                   rad/s, m/s
``observation.tcp_pose``              the tool centre point in the base frame:      m
                                      x, y, z, then the quaternion w, x, y, z
``observation.images.<slot>``         latest RGB frame, H x W x 3 uint8, top row
                                      first, by its VLA slot (else the sensor name)
``observation.depth.<sensor>``        latest depth image, H x W float32, 0 where    m
                                      there is no return
``observation.scan.<sensor>``         latest lidar scan, REP 117 ranges             m
``observation.sensors.<name>.<f>``    latest IMU / force-torque / pose reading's    SI
                                      field ``f``
``observation.base.pose``             odometry x, y, yaw                            m, rad
``observation.base.twist``            odometry vx, vy, wz                           m/s, rad/s
``observation.environment_state``     the scene's task state (object poses), its    m, wxyz
                                      entries in key order, flat (privileged only)
====================================  ============================================  ==========

A key is there when its source is: no TCP on a robot without ``sim.tcp``, no base on a
fixed arm, environment state only where the simulation is known (an env with
``privileged``, a policy with ``needs_privileged``). A policy's observation adds what only a
policy needs (:data:`ACTION_SPEC`, :data:`TIME_S`, and for privileged policies
:data:`TASK_STATE` and :data:`PRIVILEGED`); it reads the rest by the keys above.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

PREFIX = "observation."
STATE = "observation.state"
VELOCITY = "observation.velocity"
TCP_POSE = "observation.tcp_pose"
ENVIRONMENT_STATE = "observation.environment_state"
BASE_POSE = "observation.base.pose"
BASE_TWIST = "observation.base.twist"
IMAGES = "observation.images."
DEPTH = "observation.depth."
SCAN = "observation.scan."
SENSORS = "observation.sensors."

ACTION_SPEC = "action_spec"
"""(a policy's only) HAL action slot names and the hold action that keeps the robot still."""
TIME_S = "time_s"
"""(a policy's only) Seconds since the first step with a complete observation [s]."""
TASK_STATE = "task_state"
"""(a privileged policy's only) The task state by name: what ``observation.environment_state``
holds, flat."""
PRIVILEGED = "privileged"
"""(a privileged policy's only, native scenes) The simulation itself
(:class:`~openral_eval.privileged.Privileged`)."""

FloatArray: TypeAlias = npt.NDArray[np.float64]


def image_key(slot: str) -> str:
    """The key of a camera's frame by its VLA slot (``camera1``: ``observation.images.camera1``)."""
    return IMAGES + slot


def depth_key(sensor: str) -> str:
    return DEPTH + sensor


def scan_key(sensor: str) -> str:
    return SCAN + sensor


def sensor_key(sensor: str, field: str) -> str:
    """The key of one field of a state sensor's reading (``wrist_ft``, ``force``)."""
    return f"{SENSORS}{sensor}.{field}"


def vector_of(obs: Mapping[str, object], key: str) -> FloatArray | None:
    """``obs[key]`` as float64 (None: not there)."""
    value = obs.get(key)
    return None if value is None else np.asarray(value, dtype=np.float64)


def environment_state(task_state: Mapping[str, npt.ArrayLike]) -> FloatArray:
    """The task state as ``observation.environment_state``: each entry's values, flattened,
    the entries in key order (:func:`environment_names` names each value)."""
    parts = [np.asarray(task_state[key], dtype=np.float64).ravel() for key in sorted(task_state)]
    return np.concatenate(parts) if parts else np.zeros(0)


def environment_names(task_state: Mapping[str, npt.ArrayLike]) -> tuple[str, ...]:
    """A name per value of :func:`environment_state` (``cube_pos.0``, ``cube_pos.1`` …)."""
    return tuple(
        f"{key}.{i}" for key in sorted(task_state) for i in range(np.asarray(task_state[key]).size)
    )


TCP_NAMES = ("x", "y", "z", "qw", "qx", "qy", "qz")
BASE_NAMES = {BASE_POSE: ("x", "y", "yaw"), BASE_TWIST: ("vx", "vy", "wz")}
"""The names of the values of ``observation.tcp_pose`` and of the base's odometry."""


def named_vectors(
    obs: Mapping[str, object], joints: tuple[str, ...]
) -> dict[str, tuple[tuple[str, ...], FloatArray]]:
    """Every vector of ``obs`` but ``observation.state`` (key → its values' names and the
    values), as a dataset keeps them beside it: the joints' velocities (``joints`` names
    them), the TCP, the base, the state sensors' fields and the environment state (named
    by ``obs["task_state"]``'s entries); images, depth and scans are not vectors."""
    task = obs.get(TASK_STATE)
    named: dict[str, tuple[str, ...]] = {VELOCITY: joints, TCP_POSE: TCP_NAMES, **BASE_NAMES}
    if isinstance(task, Mapping):
        named[ENVIRONMENT_STATE] = environment_names(task)
    out = {}
    for key in obs:
        vector = vector_of(obs, key) if key in named or key.startswith(SENSORS) else None
        if vector is None or vector.ndim != 1:
            continue
        names = named.get(key) or tuple(f"{key.rsplit('.', 1)[-1]}.{i}" for i in range(vector.size))
        if len(names) == vector.size:
            out[key] = (names, vector)
    return out
