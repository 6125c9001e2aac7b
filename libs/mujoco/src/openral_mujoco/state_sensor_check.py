"""``robot check`` rows for the MJCF sensors an IMU, force-torque or pose sensor names.

A named MJCF sensor must exist, be of the type its field means (``gyro`` a gyro, ``force``
a force sensor, ``orientation`` a framequat, …) and sit at the manifest sensor's ``site``;
a quantity the manifest leaves out is added by the native scene, so it is not checked
here. A sensor whose site the scene creates (``mount_body``) cannot name MJCF sensors: none
can sit at a site the model does not have.
"""

from __future__ import annotations

from collections.abc import Iterator

import mujoco
from openral_core.errors import did_you_mean
from openral_core.models import StateSensor

from openral_mujoco.state_sensor_kinds import QUANTITIES, TYPE_NAMES, Quantity


def state_sensor_rows(
    field: str, sensor: StateSensor, models: list[mujoco.MjModel]
) -> Iterator[tuple[str, str, str, bool]]:
    """(field, expected, actual, ok) for each MJCF sensor ``sensor`` names."""
    for quantity in QUANTITIES[sensor.kind]:
        name: str | None = getattr(sensor, quantity.field)
        if name is None:
            continue
        where = f"{field}.{quantity.field}"
        expected = f"{name}, a {TYPE_NAMES[quantity.sensor_type]} at site {sensor.site}"
        if sensor.mount_body is not None:
            actual = "a site the scene creates (leave it out: the scene adds the sensor)"
            yield where, expected, actual, False
            continue
        actual = _actual(name, quantity, sensor.site, models)
        yield where, expected, actual, actual == "found"


def _actual(name: str, quantity: Quantity, site: str, models: list[mujoco.MjModel]) -> str:
    """``found``, or what the model has instead."""
    kind = mujoco.mjtObj.mjOBJ_SENSOR
    for model in models:
        index = mujoco.mj_name2id(model, kind, name)
        if index < 0:
            continue
        found_type = mujoco.mjtSensor(int(model.sensor_type[index]))
        if found_type != quantity.sensor_type:
            return f"a {TYPE_NAMES.get(found_type, found_type.name)} sensor"
        at_site = int(model.sensor_objtype[index]) == int(mujoco.mjtObj.mjOBJ_SITE)
        where = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, int(model.sensor_objid[index]))
        return "found" if at_site and where == site else f"a sensor at {where or 'no site'}"
    names = [
        mujoco.mj_id2name(model, kind, i) or "" for model in models for i in range(model.nsensor)
    ]
    return "not in the model" + did_you_mean(name, [n for n in names if n])
