"""Which MuJoCo sensors an IMU, force-torque or pose sensor of a manifest is made of.

One table for the three places that need it: ``robot check`` (a named MJCF sensor exists,
has the right type and sits at the sensor's site), the native scene (it adds the MuJoCo
sensors a manifest does not name) and the readers (the order and size of each reading).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
from openral_core.models import StateSensor


@dataclass(frozen=True)
class Quantity:
    """One quantity of a state sensor: the manifest field naming its MJCF sensor."""

    field: str
    """The manifest field (``accelerometer``, ``gyro``, ``orientation``, ``force``, …)."""
    sensor_type: mujoco.mjtSensor
    dim: int
    """Values in MuJoCo's ``sensordata``."""


QUANTITIES: dict[str, tuple[Quantity, ...]] = {
    "imu": (
        Quantity("accelerometer", mujoco.mjtSensor.mjSENS_ACCELEROMETER, 3),
        Quantity("gyro", mujoco.mjtSensor.mjSENS_GYRO, 3),
        Quantity("orientation", mujoco.mjtSensor.mjSENS_FRAMEQUAT, 4),
    ),
    "force_torque": (
        Quantity("force", mujoco.mjtSensor.mjSENS_FORCE, 3),
        Quantity("torque", mujoco.mjtSensor.mjSENS_TORQUE, 3),
    ),
    "pose": (
        Quantity("position", mujoco.mjtSensor.mjSENS_FRAMEPOS, 3),
        Quantity("orientation", mujoco.mjtSensor.mjSENS_FRAMEQUAT, 4),
    ),
}
"""The quantities of each state sensor kind, in the order a reading holds them."""

TYPE_NAMES = {
    mujoco.mjtSensor.mjSENS_ACCELEROMETER: "accelerometer",
    mujoco.mjtSensor.mjSENS_GYRO: "gyro",
    mujoco.mjtSensor.mjSENS_FRAMEQUAT: "framequat",
    mujoco.mjtSensor.mjSENS_FORCE: "force",
    mujoco.mjtSensor.mjSENS_TORQUE: "torque",
    mujoco.mjtSensor.mjSENS_FRAMEPOS: "framepos",
}
"""The MJCF element name of each sensor type used here."""


def mjcf_sensor_name(sensor: StateSensor, quantity: Quantity) -> str:
    """The MJCF sensor ``sensor`` reads ``quantity`` from: the one its manifest names, else
    the one a native scene adds (``<sensor name>_<field>``)."""
    named: str | None = getattr(sensor, quantity.field)
    return named if named is not None else f"{sensor.name}_{quantity.field}"
