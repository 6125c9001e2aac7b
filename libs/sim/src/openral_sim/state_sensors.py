"""The IMU, force-torque and pose sensors of a native scene, read from MuJoCo's sensors.

Composing, :func:`add_state_sensors` adds to the scene's spec the MuJoCo sensors a
manifest's state sensor does not name (at its site, named ``<sensor>_<quantity>``); the
site itself is the model's or one the scene created on ``mount_body``. After compiling,
:class:`StateSensors` finds every sensor's slice of ``sensordata`` and reads one typed
reading per manifest sensor.

A reading is what MuJoCo computed during the last ``mj_step`` (``data.sensordata``); the
readers never call ``mj_forward`` or step on the data they are given, so reading changes
nothing in the simulation. What MuJoCo's sensors measure:

- ``accelerometer``: proper acceleration of the site in its own frame, gravity included
  (a site at rest with z up reads +9.81 m/s² along z);
- ``gyro``: angular velocity of the site in its own frame [rad/s];
- ``force`` / ``torque``: what the parent body exerts on the subtree of the site's body,
  in the site's frame [N, N·m] (holding still: the subtree's weight);
- ``framepos`` / ``framequat``: the site's pose in the world frame [m; w, x, y, z].
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from openral_core.located import error_at
from openral_core.models import RobotDescription, StateSensor
from openral_mujoco.state import FloatArray
from openral_mujoco.state_sensor_kinds import QUANTITIES, mjcf_sensor_name


@dataclass(frozen=True)
class ImuReading:
    """One IMU sample (site frame; orientation in the world frame)."""

    orientation_xyzw: FloatArray
    angular_velocity: FloatArray
    """[rad/s]"""
    linear_acceleration: FloatArray
    """[m/s², gravity included]"""
    sim_time_s: float


@dataclass(frozen=True)
class WrenchReading:
    """One force-torque sample in the site frame."""

    force: FloatArray
    """[N]"""
    torque: FloatArray
    """[N·m]"""
    sim_time_s: float


@dataclass(frozen=True)
class PoseReading:
    """The site's pose in the world frame."""

    position: FloatArray
    """[m]"""
    orientation_xyzw: FloatArray
    sim_time_s: float


Reading = ImuReading | WrenchReading | PoseReading


def state_sensors_of(robot: RobotDescription) -> list[tuple[int, StateSensor]]:
    """(manifest index, sensor) of every IMU, force-torque and pose sensor."""
    return [(i, s) for i, s in enumerate(robot.sensors) if isinstance(s, StateSensor)]


def add_state_sensors(spec: mujoco.MjSpec, robot: RobotDescription) -> None:
    """Add the MuJoCo sensors each state sensor needs and its manifest does not name."""
    for _, sensor in state_sensors_of(robot):
        for quantity in QUANTITIES[sensor.kind]:
            if getattr(sensor, quantity.field) is not None:
                continue
            spec.add_sensor(
                name=mjcf_sensor_name(sensor, quantity),
                type=quantity.sensor_type,
                objtype=mujoco.mjtObj.mjOBJ_SITE,
                objname=sensor.site,
            )


class StateSensors:
    """Where each state sensor's quantities are in ``sensordata``, and its readers."""

    def __init__(self, model: mujoco.MjModel, robot: RobotDescription) -> None:
        """Find every quantity of every state sensor of ``robot`` in ``model``.

        Raises:
            ManifestError: At the sensor's field when the composed model lacks its MJCF
                sensor (``robot check`` finds this first).
        """
        self.sensors: dict[str, StateSensor] = {}
        self._slices: dict[str, list[slice]] = {}
        for index, sensor in state_sensors_of(robot):
            slices = []
            for quantity in QUANTITIES[sensor.kind]:
                name = mjcf_sensor_name(sensor, quantity)
                found = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
                if found < 0:
                    message = f"the scene has no MuJoCo sensor {name!r}"
                    raise error_at(robot, ("sensors", index, quantity.field), message)
                start = int(model.sensor_adr[found])
                slices.append(slice(start, start + quantity.dim))
            self.sensors[sensor.name] = sensor
            self._slices[sensor.name] = slices

    def read(self, name: str, data: mujoco.MjData) -> Reading:
        """The reading of sensor ``name`` from ``data`` as the last step left it (only read).

        Raises:
            KeyError: ``name`` is not a state sensor of this scene.
        """
        sensor, slices = self.sensors[name], self._slices[name]
        values = [np.array(data.sensordata[s], dtype=np.float64) for s in slices]
        time_s = float(data.time)
        if sensor.kind == "imu":
            return ImuReading(_xyzw(values[2]), values[1], values[0], time_s)
        if sensor.kind == "force_torque":
            return WrenchReading(values[0], values[1], time_s)
        return PoseReading(values[0], _xyzw(values[1]), time_s)


def _xyzw(wxyz: FloatArray) -> FloatArray:
    """MuJoCo's (w, x, y, z) quaternion in ROS's (x, y, z, w) order."""
    return np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])
