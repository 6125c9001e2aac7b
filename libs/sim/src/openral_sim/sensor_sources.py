"""Sensor capabilities as Protocols: what a sensor bridge needs from whatever has the sensor.

A simulated scene, a HAL attached to it, a robot simulated alone, or a real robot's driver
may each serve some of these; the ROS bridges depend on the Protocols only, never on a
concrete scene, so a real HAL that implements :class:`DepthSource` publishes depth through
the very bridge a simulation does.

Sensors whose frames are costly (RGB and depth cameras) are captured in two halves, so the
expensive half never runs on the control path:

1. :meth:`FrameCapture.snapshot` — on the caller's thread, holding the HAL's lock between
   two control ticks: copy what the frame will show (a MuJoCo state, a driver's buffer)
   into a holder the capture allocated for that sensor; cheap;
2. :meth:`FrameDeveloper.develop` — on a worker thread of its own, which opened the
   developer (an EGL context is current on one thread only): turn the holder into the
   frame.

Cheap sensors (lidar ray casts, state-sensor reads, odometry) are read in one call under
the lock.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Protocol, TypeVar, runtime_checkable

from openral_core.models import DepthSensor, LidarSensor, RgbSensor, StateSensor

from openral_sim.base_drive import BaseOdometry
from openral_sim.depth_cloud import DepthFrame
from openral_sim.observation import ImageArray, LidarScan
from openral_sim.state_sensors import Reading

FrameT = TypeVar("FrameT", covariant=True)


class FrameDeveloper(Protocol[FrameT]):
    """Turns snapshots into frames on the one thread that opened it."""

    def develop(self, sensor: str) -> FrameT:
        """The frame of ``sensor``'s last snapshot (it may live in a buffer the next frame
        of that sensor reuses: it is published before the next snapshot of the sensor)."""
        ...

    def close(self) -> None:
        """Release what :meth:`FrameCapture.open` made (on the same thread)."""
        ...


class FrameCapture(Protocol[FrameT]):
    """Snapshots of a live source, one holder per sensor, and the developer that renders
    them (see the module doc). The caller keeps at most one frame per sensor in flight: a
    sensor is not snapshot again before its frame is developed."""

    @property
    def sensors(self) -> tuple[str, ...]:
        """The sensors it captures, by manifest name."""
        ...

    def snapshot(self, sensor: str) -> float:
        """Copy the live state into ``sensor``'s holder; returns its time [s] (simulated,
        or wall time for a source without simulated time)."""
        ...

    def open(self) -> FrameDeveloper[FrameT]:
        """A developer for the calling thread.

        Raises:
            Exception: The thread cannot render (no GL context, say); the sensors stop.
        """
        ...


@dataclass(frozen=True)
class DepthSpec:
    """A depth sensor as served: its manifest entry and the pinhole its frames have."""

    sensor: DepthSensor
    width: int
    """[px]"""
    height: int
    """[px]"""
    fovy_deg: float
    """Vertical field of view [deg]."""
    cloud_frame: str
    """The frame its clouds are given in (the robot's base frame)."""


@dataclass(frozen=True)
class LidarSpec:
    """A planar lidar as served: its manifest entry and its scan geometry."""

    sensor: LidarSensor
    angle_min_rad: float
    angle_max_rad: float
    range_min_m: float
    range_max_m: float


@dataclass(frozen=True)
class StateSpec:
    """An IMU, force-torque or pose sensor as served: its manifest entry and the frame its
    readings are given in (the sensor's own frame; the world frame for a pose)."""

    sensor: StateSensor
    frame_id: str


@runtime_checkable
class CameraSource(Protocol):
    """Serves RGB cameras as frame captures."""

    def camera_sensors(self) -> Mapping[str, RgbSensor]:
        """The RGB sensors served, by name (empty: none)."""
        ...

    def camera_capture(
        self, out: Mapping[str, ImageArray] | None = None
    ) -> FrameCapture[ImageArray]:
        """A capture of every served camera; ``out`` gives a buffer per sensor to draw into
        (H x W x 3 uint8, the camera's size) instead of a fresh array per frame."""
        ...

    def camera_size(self) -> tuple[int, int]:
        """(height, width) of every camera frame [px]."""
        ...


@runtime_checkable
class DepthSource(Protocol):
    """Serves depth cameras (image and cloud in the robot's base frame)."""

    def depth_sensors(self) -> Mapping[str, DepthSpec]:
        """The depth sensors served, by name (empty: none)."""
        ...

    def depth_capture(self, name: str) -> FrameCapture[DepthFrame]:
        """A capture of depth sensor ``name`` (each sensor has its own size, so its own
        capture and developer).

        Raises:
            KeyError: A depth sensor not served.
        """
        ...


@runtime_checkable
class LidarSource(Protocol):
    """Serves planar lidars."""

    def lidar_sensors(self) -> Mapping[str, LidarSpec]:
        """The lidars served, by name (empty: none)."""
        ...

    def scan(self, name: str) -> LidarScan:
        """One scan of lidar ``name`` as the robot is now (under the HAL's lock).

        Raises:
            KeyError: A lidar not served.
        """
        ...


@runtime_checkable
class StateSensorSource(Protocol):
    """Serves IMU, force-torque and pose sensors."""

    def state_sensors(self) -> Mapping[str, StateSpec]:
        """The state sensors served, by name (empty: none)."""
        ...

    def read_sensor(self, name: str) -> Reading:
        """The reading of sensor ``name`` now (under the HAL's lock).

        Raises:
            KeyError: A sensor not served.
        """
        ...


@runtime_checkable
class BaseOdometrySource(Protocol):
    """Reports a mobile base's odometry."""

    def base_odometry(self) -> BaseOdometry:
        """The base's pose in the odometry frame and twist in the base frame now."""
        ...


@runtime_checkable
class ObservationFrames(Protocol):
    """Something whose steps may render sensor frames into observations, which a bridge
    that renders the same sensors itself switches off (the frames would be made twice)."""

    def render_in_observations(self, enabled: bool) -> bool:
        """Make frames in observations or not; returns what it did before."""
        ...
