"""What a scene env observes: the gymnasium ``Dict`` space and the observation in it.

Built once per env from the manifest and the scene's first observation (a sensor's frame
size is what the scene renders), so the space can never disagree with the values:

========================  ========================================================  =========
key                       value                                                     units
========================  ========================================================  =========
``joint_positions``       every manifest joint, manifest order (grippers per their  rad, m
                          read mode)
``joint_velocities``      the same joints                                           rad/s, m/s
``tcp_pose``              the tool centre point in the base frame: x, y, z, then    m
                          the quaternion w, x, y, z (a robot with a ``sim.tcp``,
                          in a native scene)
``cameras/<sensor>``      latest RGB frame, H x W x 3 uint8, top row first
``camera_slots/<slot>``   the same frame under its VLA slot (``camera1`` ...)
``depth/<sensor>``        latest depth image, H x W float32; 0 where no return      m
``lidar/<sensor>``        latest scan, REP 117 ranges (±inf out of range)           m
``state_sensors/<name>``  latest IMU / force-torque / pose reading, by field        SI
``base``                  odometry ``pose`` (x, y, yaw) and ``twist`` (vx, vy, wz)  m, rad, /s
``privileged/<key>``      the scene's task state (object poses), only when asked    m, wxyz
========================  ========================================================  =========

Each sensor keeps its manifest rate (:mod:`openral_sim.sensor_schedule`): between two of
its frames the observation repeats its latest one, as a real camera driver's last message
would. A kind with no sensor has no key.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields

import numpy as np
import numpy.typing as npt
from gymnasium import spaces
from openral_core.loaded import LoadedRobot
from openral_mujoco.state import JointStateSample
from openral_sim.observation import Observation as SceneObservation
from openral_sim.state_sensors import Reading

EnvObservation = dict[str, object]
"""One observation in :attr:`ObservationLayout.space` (nested dicts of numpy arrays)."""

_INF = np.inf


def _box(like: npt.NDArray[np.generic], low: float = -_INF, high: float = _INF) -> spaces.Box:
    """A Box of ``like``'s shape and dtype (uint8 images: 0..255)."""
    if like.dtype == np.uint8:
        return spaces.Box(0, 255, like.shape, np.uint8)
    return spaces.Box(low, high, like.shape, like.dtype.type)  # type: ignore[arg-type]


def _depth_image(depth_m: npt.NDArray[np.floating]) -> npt.NDArray[np.float32]:
    """The depth image with 0 where the sensor has no return (NaN in the scene's frame)."""
    return np.nan_to_num(depth_m.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)


_FIELDS: dict[type, tuple[str, ...]] = {}
"""Vector fields of each reading type (its time stamp is the observation's)."""


def _reading(reading: Reading) -> dict[str, npt.NDArray[np.float64]]:
    """A state-sensor reading's vector fields."""
    kind = type(reading)
    if kind not in _FIELDS:
        _FIELDS[kind] = tuple(f.name for f in fields(reading) if f.name != "sim_time_s")
    return {name: np.asarray(getattr(reading, name), dtype=np.float64) for name in _FIELDS[kind]}


class ObservationLayout:
    """The observation space of one scene env and the observations in it (module doc)."""

    def __init__(
        self,
        robot: LoadedRobot,
        first: SceneObservation,
        joints: JointStateSample,
        *,
        privileged: bool,
        tcp_pose: npt.NDArray[np.float64] | None = None,
        only: frozenset[str] | None = None,
    ) -> None:
        """Lay out the space from ``first``, an observation with every sensor's frame, and
        the HAL's joint sample of the same instant; ``only``: keep just these sensors (for
        a backend that renders every camera whatever the env asks; None: all it gives)."""
        self.only = only
        slots = {slot.sensor: slot.slot for slot in robot.tables.vla_slots}
        self.slots = {
            sensor: slot
            for sensor, slot in slots.items()
            if sensor in first.images and (only is None or sensor in only)
        }
        self.privileged = privileged
        self._latest: dict[str, dict[str, object]] = {}
        """Sensor kind → sensor → its newest frame."""
        self.space = spaces.Dict(self._spaces(self.observe(first, joints, tcp_pose)))

    def _spaces(self, obs: EnvObservation, low: float = -_INF) -> dict[str, spaces.Space[object]]:
        """The space of an observation like ``obs`` (values no lower than ``low``)."""
        out: dict[str, spaces.Space[object]] = {}
        for key, value in obs.items():
            if isinstance(value, dict):
                out[key] = spaces.Dict(self._spaces(value, 0.0 if key == "depth" else low))
            else:
                out[key] = _box(np.asarray(value), low)
        return out

    def reset(self) -> None:
        """Forget the latest frames (a new episode's first observation brings them all)."""
        self._latest = {}

    def observe(
        self,
        obs: SceneObservation,
        joints: JointStateSample,
        tcp_pose: npt.NDArray[np.float64] | None = None,
    ) -> EnvObservation:
        """The env observation of the scene's ``obs`` (latest frame of each sensor), the
        HAL's ``joints`` (manifest order and units; a robosuite scene's read by name) and
        the TCP's pose (base frame), when the robot has one here."""
        out: EnvObservation = {
            "joint_positions": np.array(joints.positions, dtype=np.float64),
            "joint_velocities": np.array(joints.velocities, dtype=np.float64),
        }
        if tcp_pose is not None:
            out["tcp_pose"] = tcp_pose
        if obs.images:  # (each kind only when it has news: this runs every step)
            self._keep("cameras", obs.images)
        if obs.depth:
            self._keep("depth", {n: _depth_image(f.depth_m) for n, f in obs.depth.items()})
        if obs.scans:
            self._keep("lidar", {n: scan.ranges for n, scan in obs.scans.items()})
        if obs.readings:
            self._keep("state_sensors", {n: _reading(r) for n, r in obs.readings.items()})
        for kind, frames in self._latest.items():
            out[kind] = _copied(frames)
        cameras = out.get("cameras")
        if isinstance(cameras, dict) and self.slots:
            out["camera_slots"] = {self.slots[n]: cameras[n] for n in self.slots if n in cameras}
        if obs.odometry is not None:
            odom = obs.odometry
            out["base"] = {
                "pose": np.array([odom.x_m, odom.y_m, odom.yaw_rad]),
                "twist": np.array([odom.vx_m_s, odom.vy_m_s, odom.wz_rad_s]),
            }
        if self.privileged:
            out["privileged"] = _task_state(obs.task_state)
        return out

    def _keep(self, kind: str, frames: Mapping[str, object]) -> None:
        """Remember the newest frame of each sensor of ``kind`` (of ``only``'s)."""
        if self.only is not None:
            frames = {name: frame for name, frame in frames.items() if name in self.only}
            if not frames:
                return
        self._latest.setdefault(kind, {}).update(frames)


def _copied(frames: Mapping[str, object]) -> dict[str, object]:
    """Fresh copies of the kept frames: every observation owns its arrays (a user may keep
    or change one), as gymnasium's checker requires."""
    return {
        name: _copied(value) if isinstance(value, dict) else np.array(value, copy=True)
        for name, value in frames.items()
    }


def _task_state(state: Mapping[str, npt.NDArray[np.floating]]) -> dict[str, object]:
    return {key: np.asarray(value, dtype=np.float64).copy() for key, value in state.items()}
