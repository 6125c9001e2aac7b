"""What a scene env observes: the gymnasium ``Dict`` space and the observation in it.

The observation is the one every path shares (:mod:`openral_eval.observation_keys`):
a flat ``Dict`` by LeRobot's keys (``observation.state``, ``observation.velocity``,
``observation.tcp_pose``, ``observation.images.<slot>`` …), each image once. It is laid
out once per env from the manifest and the scene's first observation (a sensor's frame
size is what the scene renders), so the space can never disagree with the values.
``keys`` keeps only the keys named (a trainer that wants joints and the TCP only);
``flat`` joins the kept keys, in key order, into one float64 vector, as robosuite's
``GymWrapper`` does (:class:`FlatLayout`).

Each sensor keeps its manifest rate (:mod:`openral_sim.sensor_schedule`): between two of
its frames the observation repeats its latest one, as a real camera driver's last message
would. A sensor that is not there has no key.
"""

from __future__ import annotations

from dataclasses import fields, replace

import numpy as np
import numpy.typing as npt
from gymnasium import spaces
from openral_core.loaded import LoadedRobot
from openral_mujoco.state import JointStateSample
from openral_sim.depth_cloud import DepthFrame
from openral_sim.observation import Observation as SceneObservation
from openral_sim.rollout import SensorSuite
from openral_sim.state_sensors import Reading

from openral_eval import observation_keys as keys

EnvObservation = dict[str, object]
"""One observation in :attr:`ObservationLayout.space`: key → numpy array (flat), or one
vector (:class:`FlatLayout`)."""

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


def _reading_fields(reading: Reading) -> tuple[str, ...]:
    """A state-sensor reading's vector fields."""
    kind = type(reading)
    if kind not in _FIELDS:
        _FIELDS[kind] = tuple(f.name for f in fields(reading) if f.name != "sim_time_s")
    return _FIELDS[kind]


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
        self.slots = {slot.sensor: slot.slot for slot in robot.tables.vla_slots}
        """Camera → its VLA slot (every camera has one: its feature key's, else its name)."""
        self.privileged = privileged
        self._latest: dict[str, object] = {}
        """Key → the newest frame of a sensor."""
        self._readings: dict[str, tuple[tuple[str, str], ...]] = {}
        """State sensor → (field, key) of each of its vector fields."""
        sample = self.observe(first, joints, tcp_pose)
        state = first.task_state if privileged else {}
        self.environment_names = keys.environment_names(state)
        """A name per value of ``observation.environment_state`` (``cube_pos.0`` …)."""
        self._entries = {key: np.shape(state[key]) for key in sorted(state)}
        self.space = spaces.Dict(
            {
                key: _box(np.asarray(value), 0.0 if key.startswith(keys.DEPTH) else -_INF)
                for key, value in sample.items()
            }
        )

    def task_state(self, environment_state: npt.ArrayLike) -> dict[str, npt.NDArray[np.float64]]:
        """``observation.environment_state`` by entry again (``red_cube_pos`` → its 3
        values), as the scene reports its task state."""
        flat, out, at = np.asarray(environment_state, dtype=np.float64), {}, 0
        for key, shape in self._entries.items():
            size = int(np.prod(shape))
            out[key] = flat[at : at + size].reshape(shape)
            at += size
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
            keys.STATE: np.array(joints.positions, dtype=np.float64),
            keys.VELOCITY: np.array(joints.velocities, dtype=np.float64),
        }
        if tcp_pose is not None:
            out[keys.TCP_POSE] = np.array(tcp_pose, dtype=np.float64)
        self._keep_news(obs)
        # fresh copies: every observation owns its arrays, as gymnasium's checker requires
        out.update({key: np.array(frame, copy=True) for key, frame in self._latest.items()})
        if obs.odometry is not None:
            odom = obs.odometry
            out[keys.BASE_POSE] = np.array([odom.x_m, odom.y_m, odom.yaw_rad])
            out[keys.BASE_TWIST] = np.array([odom.vx_m_s, odom.vy_m_s, odom.wz_rad_s])
        if self.privileged:
            out[keys.ENVIRONMENT_STATE] = keys.environment_state(obs.task_state)
        return out

    def _keep_news(self, obs: SceneObservation) -> None:
        """Remember the newest frame of each sensor (of ``only``'s) that has news (this runs
        every step: a kind without news costs nothing)."""
        news: list[tuple[str, str, object]] = []
        if obs.images:
            news += [(n, keys.image_key(self.slots.get(n, n)), f) for n, f in obs.images.items()]
        if obs.depth:
            news += [(n, keys.depth_key(n), _depth_image(f.depth_m)) for n, f in obs.depth.items()]
        if obs.scans:
            news += [(n, keys.scan_key(n), scan.ranges) for n, scan in obs.scans.items()]
        for sensor, key, frame in news:
            if self.only is None or sensor in self.only:
                self._latest[key] = frame
        for name, reading in (obs.readings or {}).items():
            for field, key in self._reading_keys(name, reading):
                self._latest[key] = np.asarray(getattr(reading, field), dtype=np.float64)

    def _reading_keys(self, name: str, reading: Reading) -> tuple[tuple[str, str], ...]:
        """(field, key) of each vector field of sensor ``name``'s reading (none when
        ``only`` leaves the sensor out), looked up once per sensor: readings come every
        step."""
        found = self._readings.get(name)
        if found is None:
            kept = self.only is None or name in self.only
            found = tuple(
                (field, keys.sensor_key(name, field)) for field in _reading_fields(reading) if kept
            )
            self._readings[name] = found
        return found


class FlatLayout:
    """The kept keys of an :class:`ObservationLayout`'s observations, in key order, as one
    float64 vector (robosuite's ``GymWrapper``); :attr:`slices` says where each key is."""

    def __init__(self, space: spaces.Dict, kept: tuple[str, ...]) -> None:
        self.keys = tuple(sorted(kept))
        self.slices: dict[str, slice] = {}
        lows, highs, at = [], [], 0
        for key in self.keys:
            box = space[key]
            assert isinstance(box, spaces.Box)
            size = int(np.prod(box.shape))
            self.slices[key] = slice(at, at + size)
            lows.append(np.asarray(box.low, dtype=np.float64).ravel())
            highs.append(np.asarray(box.high, dtype=np.float64).ravel())
            at += size
        self.space = spaces.Box(np.concatenate(lows), np.concatenate(highs), dtype=np.float64)

    def flat(self, obs: EnvObservation) -> npt.NDArray[np.float64]:
        """``obs``'s kept keys as one vector."""
        return np.concatenate([np.asarray(obs[key], dtype=np.float64).ravel() for key in self.keys])


def blank_frames(
    sensors: SensorSuite, observed: frozenset[str] | None, like: SceneObservation
) -> SceneObservation:
    """``like`` (an observation of a native scene that rendered nothing) with a black frame
    of every camera and depth sensor of ``observed`` (None: all) at the size the scene
    renders, and a scan and a reading of each lidar and state sensor (no renderer needed).

    An env lays out its spaces from this, so building one opens no OpenGL context: a
    process that built an env to learn the spaces (gymnasium's ``AsyncVectorEnv`` does)
    can still fork workers that render."""

    def chosen(name: str) -> bool:
        return observed is None or name in observed

    height, width = sensors.camera_size()
    images = {
        n: np.zeros((height, width, 3), np.uint8) for n in sensors.camera_sensors() if chosen(n)
    }
    depth = {
        n: DepthFrame(
            np.zeros((s.height, s.width), np.float32), np.zeros((0, 3), np.float32), like.time_s
        )
        for n, s in sensors.depth_sensors().items()
        if chosen(n)
    }
    scans = {n: sensors.scan(n) for n in sensors.lidar_sensors() if chosen(n)}
    readings = {n: sensors.read_sensor(n) for n in sensors.state_sensors() if chosen(n)}
    return replace(like, images=images, depth=depth, scans=scans, readings=readings)


def kept_keys(space: spaces.Dict, wanted: tuple[str, ...] | None) -> tuple[str, ...]:
    """The keys an env keeps: ``wanted`` (None: all of ``space``), each once.

    Raises:
        ValueError: None kept, or a key ``space`` does not have (the line lists those it has).
    """
    have = tuple(space.spaces)
    if wanted is None:
        return have
    unknown = [key for key in wanted if key not in have]
    if unknown or not wanted:
        raise ValueError(
            f"env config keys {unknown or '()'} are not in this scene's observation; "
            f"valid: {sorted(have)}"
        )
    return tuple(dict.fromkeys(wanted))
