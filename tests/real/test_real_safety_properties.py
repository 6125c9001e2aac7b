"""The real path's safety rules as properties, on the emulated SO-101 (not hardware): for any
sequence of commands, a refused one changes nothing, and every goal the driver writes stays
inside the calibrated range and no further from the last one than the velocity limits
allow in a control period."""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from openral_core import open_robot_by_id
from openral_hal.errors import ActionRejected
from openral_real.emulator.emulated_bus import EmulatedBus
from openral_real.feetech_hal import FeetechHal

from tests.real.conftest import Rig, beside_others, calibrate

PER_RAD = 4096 / (2 * math.pi)


@pytest.fixture(scope="module")
def connected(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Rig, FeetechHal]]:
    robot = beside_others(open_robot_by_id("so101"))
    with EmulatedBus(robot, seed=5) as bus:
        file = Path(tmp_path_factory.mktemp("cal")) / "so101.json"
        calibrate(robot, bus.path, file)
        rig = Rig(robot, bus, file)
        hal = rig.hal()
        hal.connect()
        yield rig, hal
        hal.disconnect()


value = st.floats(-4.0, 4.0, allow_nan=False)
bad = st.sampled_from(["nan", "inf", "short", "long", "zeros"])
command = st.one_of(st.lists(value, min_size=6, max_size=6), bad)


def _action(kind: object) -> np.ndarray:
    if kind == "nan":
        return np.array([0.1, np.nan, 0.0, 0.0, 0.0, 0.5])
    if kind == "inf":
        return np.array([np.inf, 0.1, 0.0, 0.0, 0.0, 0.5])
    if kind == "short":
        return np.full(5, 0.2)
    if kind == "long":
        return np.full(7, 0.2)
    if kind == "zeros":
        return np.zeros(6)
    return np.array(kind, dtype=np.float64)


@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(st.lists(command, min_size=1, max_size=6))
def test_commands_stay_inside_the_envelope_and_refusals_change_nothing(
    connected: tuple[Rig, FeetechHal], commands: list[object]
) -> None:
    rig, hal = connected
    assert not hal.estopped, hal.estop_reason
    began = time.time()
    session = hal._running()
    for kind in commands:
        before = session.envelope.target
        if isinstance(kind, str) or not any(kind):  # an all-zero list is refused too
            with pytest.raises(ActionRejected):
                hal.send_action(_action(kind))
            assert np.array_equal(session.envelope.target, before)
        else:
            hal.send_action(_action(kind))
        time.sleep(0.03)
    goals = [
        [int(item.split("=")[1]) for item in line.split()[3:]]
        for line in rig.bus.written("Goal_Position", began)
    ]
    calibration = [session.units.scales[i].calibration for i in range(6)]
    step_limit = 10.0 * hal.control_period_s * PER_RAD + 1  # velocity limit x period [steps]
    for previous, goal in itertools.pairwise(goals):
        assert max(abs(a - b) for a, b in zip(previous, goal, strict=True)) <= step_limit
    for goal in goals:
        for motor, steps in zip(calibration, goal, strict=True):
            assert motor.range_min <= steps <= motor.range_max
