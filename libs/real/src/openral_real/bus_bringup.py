"""Bringing a Feetech bus up: read everything before writing anything, then hold the arm
where it is.

1. every motor answers and is the manifest's model (pings; nothing written yet);
2. the servos hold the calibration file's offsets and ranges (read back; a difference is
   refused with the command that writes the file to them, nothing written);
3. the present block is read; a servo reporting a fault is refused;
4. EEPROM unlocked, position mode and the manifest's ``settings`` written where they
   differ from what the servo holds (EEPROM is spared);
5. every goal written *at the position just read* (to the step), then torque on and the
   EEPROM locked: the arm is held where it was, nothing jumps.
"""

from __future__ import annotations

from collections.abc import Mapping

from openral_core.servo_models import fault_text

from openral_real.calibration import MotorCalibration
from openral_real.errors import BusError
from openral_real.feetech_bus import FeetechBus, ServoReading

CALIBRATION_REGISTERS = {
    "Homing_Offset": "homing_offset",
    "Min_Position_Limit": "range_min",
    "Max_Position_Limit": "range_max",
}
"""The servo registers a calibration is written to, and its field each holds."""


def bring_up(
    bus: FeetechBus, calibration: Mapping[str, MotorCalibration], fix: str
) -> list[ServoReading]:
    """Steps 1 to 5 (see the module doc); the present block the arm is held at.

    Args:
        bus: The open bus.
        calibration: The arm's calibration, by joint.
        fix: What to do when the servos hold another calibration (said in the refusal).

    Raises:
        BusError: A missing motor, another model, another calibration in the servos, a
            servo fault. BusFault: The bus failed meanwhile.
    """
    bus.check_motors()
    check_calibrated(bus, calibration, fix)
    readings = bus.read_present()
    faulty = [(i, r) for i, r in zip(bus.ids, readings, strict=True) if r.faults]
    if faulty:
        servo_id, reading = faulty[0]
        raise BusError(
            f"{bus.names[servo_id]} reports {fault_text(reading.faults)}; clear it (power the "
            "servo off and on) before driving the arm"
        )
    for motor in bus.wiring.motors:
        bus.write("Lock", motor.id, 0)
        wanted = {"Operating_Mode": 0, **motor.settings}
        for name, value in wanted.items():
            if bus.read(name, motor.id) != value:
                bus.write(name, motor.id, value)
    bus.write_goals([r.position for r in readings])  # where the arm is: no jump
    for motor in bus.wiring.motors:
        bus.write("Torque_Enable", motor.id, 1)
        bus.write("Lock", motor.id, 1)
    return readings


def check_calibrated(
    bus: FeetechBus, calibration: Mapping[str, MotorCalibration], fix: str
) -> None:
    """The servos hold ``calibration`` (read back; else one line, nothing written).

    Raises:
        BusError: A register that differs from the file.
    """
    for motor in bus.wiring.motors:
        expected = calibration[motor.joint]
        for register, field in CALIBRATION_REGISTERS.items():
            held, wanted = bus.read(register, motor.id), getattr(expected, field)
            if held != wanted:
                raise BusError(
                    f"{bus.names[motor.id]} holds {register} {held} but the calibration says "
                    f"{wanted}: the servos hold another calibration; {fix} (nothing was "
                    "written to the bus)"
                )
