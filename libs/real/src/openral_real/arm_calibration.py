"""Calibrating a Feetech arm, step by step, as LeRobot does it.

1. :func:`record_homing`: torque off, the servos' calibration reset (Homing_Offset 0,
   limits 0..4095), and with the arm held in the middle of every joint's range, each homing
   offset set so that the present position there reads 2047 (half a turn).
2. :func:`record_ranges`: the user moves every joint through its whole travel; the lowest
   and highest present positions seen are its range. Without a user
   (:func:`ranges_from_limits`) the range is the manifest's position limits around the
   middle the arm was homed at.
3. :func:`apply_calibration`: the offsets and ranges are written to the servos (EEPROM,
   torque off), as LeRobot writes them, and the file is written in LeRobot's format.

Every step reads or writes through :class:`~openral_real.feetech_bus.FeetechBus`; nothing
drives a motor (torque stays off throughout).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from openral_core.models import LimitedJoint, RobotDescription
from openral_core.real_wiring import FeetechWiring

from openral_real.calibration import HALF_TURN, MotorCalibration
from openral_real.errors import BusFault
from openral_real.feetech_bus import FeetechBus

RANGE_POLL_S = 0.02
"""How often the range recording reads the arm [s]."""
MISSED_READS = 3
"""Reads in a row that may fail while the ranges are recorded before the recording ends
with the bus's error: a reply lost once (noise on the wire, a busy host) must not throw
away the minute the user spent moving the arm."""


def release(bus: FeetechBus) -> None:
    """Torque off and EEPROM unlocked on every motor (the arm can be moved by hand)."""
    for servo_id in bus.ids:
        bus.write("Torque_Enable", servo_id, 0)
        bus.write("Lock", servo_id, 0)


def record_homing(bus: FeetechBus) -> dict[int, int]:
    """Reset each servo's calibration and home it where the arm is now (step 1).

    Returns:
        Bus id → its homing offset [steps].
    """
    release(bus)
    for servo_id in bus.ids:
        bus.write("Homing_Offset", servo_id, 0)
        bus.write("Min_Position_Limit", servo_id, 0)
        bus.write("Max_Position_Limit", servo_id, 4095)
    offsets = {}
    for servo_id, reading in zip(bus.ids, bus.read_present(), strict=True):
        offsets[servo_id] = reading.position - HALF_TURN
        bus.write("Homing_Offset", servo_id, offsets[servo_id])
    return offsets


def record_ranges(
    bus: FeetechBus,
    done: Callable[[], bool],
    seen: Callable[[dict[int, tuple[int, int, int]]], None] | None = None,
) -> dict[int, tuple[int, int]]:
    """The lowest and highest present position of each motor while the user moves the arm,
    until ``done()`` is true (step 2).

    Args:
        bus: The arm's bus (homed).
        done: Polled between reads; True ends the recording.
        seen: Called after each read with id → (present, lowest, highest).

    Raises:
        BusFault: :data:`MISSED_READS` reads in a row failed (the last one's error).
    """
    low: dict[int, int] = {}
    high: dict[int, int] = {}
    missed = 0
    while True:
        try:
            readings = bus.read_present()
        except BusFault:
            missed += 1
            if missed >= MISSED_READS:
                raise
            time.sleep(RANGE_POLL_S)
            continue
        missed = 0
        now = {}
        for servo_id, reading in zip(bus.ids, readings, strict=True):
            low[servo_id] = min(low.get(servo_id, reading.position), reading.position)
            high[servo_id] = max(high.get(servo_id, reading.position), reading.position)
            now[servo_id] = (reading.position, low[servo_id], high[servo_id])
        if seen is not None:
            seen(now)
        if done():
            return {i: (low[i], high[i]) for i in bus.ids}
        time.sleep(RANGE_POLL_S)


def ranges_from_limits(robot: RobotDescription, bus: FeetechWiring) -> dict[int, tuple[int, int]]:
    """Each motor's range from its joint's position limits, the arm homed in their middle."""
    joints = {joint.name: joint for joint in robot.joints}
    per_rad = bus.resolution / (2.0 * math.pi)
    ranges = {}
    for motor in bus.motors:
        joint = joints[motor.joint]
        low, high = joint.position_limits if isinstance(joint, LimitedJoint) else (-1.0, 1.0)
        half = (high - low) / 2.0 * per_rad
        ranges[motor.id] = (max(0, round(HALF_TURN - half)), min(4095, round(HALF_TURN + half)))
    return ranges


def calibration_of(
    bus: FeetechWiring, offsets: dict[int, int], ranges: dict[int, tuple[int, int]]
) -> dict[str, MotorCalibration]:
    """The calibration, by joint in manifest order, in LeRobot's fields."""
    return {
        motor.joint: MotorCalibration(
            id=motor.id,
            drive_mode=0,
            homing_offset=offsets[motor.id],
            range_min=ranges[motor.id][0],
            range_max=ranges[motor.id][1],
        )
        for motor in bus.motors
    }


def apply_calibration(bus: FeetechBus, calibration: dict[str, MotorCalibration]) -> None:
    """Write every motor's offset and range into its EEPROM (torque off), then lock it."""
    release(bus)
    for motor in calibration.values():
        bus.write("Homing_Offset", motor.id, motor.homing_offset)
        bus.write("Min_Position_Limit", motor.id, motor.range_min)
        bus.write("Max_Position_Limit", motor.id, motor.range_max)
        bus.write("Lock", motor.id, 1)
