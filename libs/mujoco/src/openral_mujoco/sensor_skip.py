"""Physics steps that leave MuJoCo's sensors alone: only the state at the end of a control
period is ever read.

``mj_step`` computes every sensor at every physics step (a force-torque sensor costs a
second pass over the dynamics: 0.7 µs a step on the Panda, about 3 % of a 20 Hz control
period of 25 steps), yet a scene reads its sensors only after the period's last step, when
it calls ``mj_forward`` for the state the data then holds, which computes them all again.
Sensors feed nothing back into the physics, so skipping them in between changes no
trajectory, bit for bit.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import mujoco

_SENSORS_OFF = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)


@contextmanager
def sensors_skipped(model: mujoco.MjModel) -> Iterator[None]:
    """Steps taken inside compute no sensors; the model's own flags come back after
    (an exception included), so a model that had sensors off keeps them off."""
    flags = int(model.opt.disableflags)
    model.opt.disableflags = flags | _SENSORS_OFF
    try:
        yield
    finally:
        model.opt.disableflags = flags
