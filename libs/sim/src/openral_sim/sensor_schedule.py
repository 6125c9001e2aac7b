"""When each sensor produces a sample: one rule for every sensor kind, on every path.

A sensor's rate is its manifest ``rate_hz``. A frame-rate override (``deploy sim
--camera-rate``) replaces the rate of every imaging sensor alike: RGB and depth cameras and
lidars; IMU, force-torque and pose sensors keep their own. Every rate is then capped at the
control rate: the physics changes only when the scene steps, so sampling faster would only
repeat the last sample.

:func:`sensor_rates` gives the rates (the ROS bridges schedule their publishers with them);
:class:`SensorSchedule` says which sensors are due at a simulated time (a scene fills an
observation with the frames due at that step, so a sweep renders a 10 Hz camera at 10 Hz
whatever the control rate).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

from openral_core.models import DepthSensor, LidarSensor, RgbSensor, RobotDescription

IMAGING = (RgbSensor, DepthSensor, LidarSensor)
"""Sensor kinds a frame-rate override applies to."""

_EPS_S = 1e-9
"""Tolerance on due times [s] (control periods are sums of float physics steps)."""


def sensor_rates(
    robot: RobotDescription,
    control_rate_hz: float | None,
    *,
    frame_rate_hz: float | None = None,
    sensors: Iterable[str] | None = None,
) -> dict[str, float]:
    """The rate of each sensor [Hz], by manifest sensor name (see the module doc).

    Args:
        robot: The manifest.
        control_rate_hz: How often the scene is stepped [Hz]; no rate exceeds it (None:
            no cap, a real robot's sensors keep their own time).
        frame_rate_hz: Overrides the rate of every RGB, depth and lidar sensor (None:
            each sensor's own; ``math.inf``: every control step).
        sensors: Only these sensors (None: all of the manifest's).

    Raises:
        ValueError: A rate that is not positive and finite.
    """
    if control_rate_hz is not None and not (math.isfinite(control_rate_hz) and control_rate_hz > 0):
        raise ValueError(f"control rate must be a positive number of Hz, got {control_rate_hz}")
    if frame_rate_hz is not None and not frame_rate_hz > 0:
        raise ValueError(f"frame rate must be a positive number of Hz, got {frame_rate_hz}")
    if frame_rate_hz == math.inf and control_rate_hz is None:
        raise ValueError("a frame rate of every step needs a control rate")
    wanted = None if sensors is None else set(sensors)
    rates: dict[str, float] = {}
    for sensor in robot.sensors:
        if wanted is not None and sensor.name not in wanted:
            continue
        rate = float(sensor.rate_hz)
        if frame_rate_hz is not None and isinstance(sensor, IMAGING):
            rate = float(frame_rate_hz)
        rates[sensor.name] = rate if control_rate_hz is None else min(rate, control_rate_hz)
    return rates


class SensorSchedule:
    """Which sensors are due at a simulated time, each at its own rate.

    Every sensor is due at :meth:`restart`'s instant, then once per period of simulated
    time; a step that jumps over several periods makes it due once, not once per period
    missed (no bursts after a pause).
    """

    def __init__(self, rates_hz: Mapping[str, float]) -> None:
        """Args: rates_hz: Sensor name → rate [Hz] (as :func:`sensor_rates` gives)."""
        self.periods_s = {name: 1.0 / rate for name, rate in rates_hz.items()}
        self._next_s: dict[str, float] = dict.fromkeys(self.periods_s, -math.inf)

    def restart(self) -> None:
        """Every sensor is due at the next :meth:`due` (a new episode)."""
        self._next_s = dict.fromkeys(self.periods_s, -math.inf)

    def due(self, time_s: float) -> frozenset[str]:
        """The sensors due at ``time_s`` [s]; their next due times move one period on."""
        due: list[str] = []
        for name, next_s in self._next_s.items():
            if time_s + _EPS_S >= next_s:
                due.append(name)
                period = self.periods_s[name]
                start = next_s if math.isfinite(next_s) else time_s
                following = start + period
                self._next_s[name] = following if following > time_s + _EPS_S else time_s + period
        return frozenset(due)
