"""Bus faults through the emulator: each latches the E-stop within two control periods with
one line naming the motor (or the port) and the fault, and no goal is written after it; a
bus with a fault at connect is refused with nothing written. On the emulator, not on
hardware. The latencies are real time: these run in the exclusive phase."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import pytest
from openral_core import LoadedRobot, open_robot_by_id
from openral_hal.errors import ConfigurationError
from openral_real.emulator.bus_emulator import Fault
from openral_real.emulator.emulated_bus import EmulatedBus
from openral_real.feetech_hal import FeetechHal

from tests.real.conftest import Rig
from tests.real.test_feetech_hal import wait_for

pytestmark = pytest.mark.exclusive
PERIOD_S = 0.01
"""The so101's control period (real.control_rate_hz 100)."""


@pytest.fixture
def so101() -> LoadedRobot:
    """The SO-101 as it ships: 100 Hz, 5 ms for a reply."""
    return open_robot_by_id("so101")


FAULTS: dict[str, tuple[Callable[[EmulatedBus], None], str]] = {
    "silent motor": (
        lambda bus: bus.emulator.inject(3, Fault.SILENT),
        "motor 3 (elbow_flex) stopped answering",
    ),
    "checksum storm": (
        lambda bus: setattr(bus.emulator, "corrupt_share", 1.0),
        "motor 1 (shoulder_pan) sent a corrupt reply",
    ),
    "overload": (
        lambda bus: bus.emulator.inject(2, Fault.OVERLOAD),
        "motor 2 (shoulder_lift) reports overload",
    ),
    "over-temperature": (
        lambda bus: bus.emulator.inject(5, Fault.OVERHEAT),
        "motor 5 (wrist_roll) reports over-temperature",
    ),
    "unplug": (lambda bus: bus.pty.unplug(), "the bus on /dev/pts/"),
}


def _moving(hal: FeetechHal) -> None:
    """Aim at a far pose, so goals are written every cycle when the fault comes."""
    target = hal.hold_action()
    target[:3] += [0.8, -0.5, 0.6]
    hal.send_action(target)
    time.sleep(0.15)


@pytest.mark.parametrize("fault", list(FAULTS))
def test_a_fault_latches_within_two_periods_and_nothing_moves_after(rig: Rig, fault: str) -> None:
    inject, said = FAULTS[fault]
    hal = rig.hal()
    hal.connect()
    try:
        _moving(hal)
        injected = time.time()
        inject(rig.bus)
        assert wait_for(lambda: hal.estopped, 1.0)
        assert hal.estop_at is not None
        assert hal.estop_at - injected <= 2 * PERIOD_S, f"latched after {hal.estop_at - injected}"
        assert len(rig.faults) == 1 and said in rig.faults[0], rig.faults
        time.sleep(0.2)
        assert rig.bus.written("Goal_Position", after=hal.estop_at) == []
        positions = hal.read_state().positions.copy() if fault != "unplug" else None
        with pytest.raises(Exception, match="E-stop is latched"):
            hal.send_action(hal.hold_action() if positions is not None else np.ones(6))
    finally:
        hal.disconnect()


def test_after_the_fault_clears_a_restart_drives_again(rig: Rig) -> None:
    hal = rig.hal()
    hal.connect()
    rig.bus.emulator.inject(4, Fault.SILENT)
    assert wait_for(lambda: hal.estopped, 1.0)
    hal.disconnect()
    rig.bus.emulator.clear()
    again = rig.hal()
    again.connect()
    try:
        target = again.hold_action()
        target[3] += 0.3
        again.send_action(target)
        assert wait_for(lambda: abs(again.read_state().positions[3] - target[3]) < 0.01, 5)
    finally:
        again.disconnect()


def test_a_missing_motor_at_connect_is_one_line_and_nothing_is_written(
    rig: Rig, so101: LoadedRobot
) -> None:
    rig.bus.emulator.inject(6, Fault.SILENT)
    written = len([line for line in rig.bus.lines if "WRITE" in line])
    with pytest.raises(ConfigurationError) as raised:
        rig.hal().connect()
    message = str(raised.value)
    assert "motor 6 (gripper) does not answer" in message and "\n" not in message
    assert "nothing was written to the bus" in message
    assert len([line for line in rig.bus.lines if "WRITE" in line]) == written


def test_a_faulty_motor_at_connect_is_refused(rig: Rig) -> None:
    rig.bus.emulator.inject(1, Fault.VOLTAGE)
    with pytest.raises(ConfigurationError, match=r"motor 1 .* reports input voltage out of range"):
        rig.hal().connect()
    assert [s.get("Torque_Enable") for s in rig.bus.emulator.servos.values()] == [0] * 6
