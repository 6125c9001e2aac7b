"""``openral robot calibrate`` on the emulated SO-101 (not on hardware): the interactive
steps with a hand moving the arm, the non-interactive mode, and a calibration made LeRobot's
way giving the driver the same radians as its own."""

from __future__ import annotations

import json
import math
import subprocess
import time
from pathlib import Path

import pytest
from openral_core import LoadedRobot
from openral_core.models import LimitedJoint
from openral_hal.factory import RealOptions
from openral_real import arm_calibration
from openral_real.calibration import MotorCalibration, read_calibration, write_calibration
from openral_real.emulator.emulated_bus import EmulatedBus
from openral_real.errors import BusFault
from openral_real.feetech_bus import ServoReading
from openral_real.feetech_hal import FeetechHal

from tests.real.conftest import Rig, open_bus
from tests.real.deploy_helpers import openral

PER_RAD = 4096 / (2 * math.pi)


def _limits(robot: LoadedRobot) -> dict[str, tuple[float, float]]:
    return {
        j.name: (j.position_limits[0], j.position_limits[1])
        for j in robot.description.joints
        if isinstance(j, LimitedJoint)
    }


def _sweep(bus: EmulatedBus, robot: LoadedRobot, pause_s: float) -> None:
    """A hand moves every joint to both ends of its range and back to the middle."""
    for joint, (low, high) in _limits(robot).items():
        for angle in (low, high, (low + high) / 2):
            bus.arm.place(joint, angle)
            time.sleep(pause_s)


def _enter(process: subprocess.Popen[str]) -> None:
    """The user presses ENTER; a process that already ended says why."""
    assert process.stdin is not None
    try:
        process.stdin.write("\n")
        process.stdin.flush()
    except BrokenPipeError:
        _, err = process.communicate(timeout=30)
        pytest.fail(f"calibrate ended early (exit {process.returncode}): {err}")


class _FlakyBus:
    """Two motors whose present block is lost on the reads numbered in ``lost``."""

    ids = (1, 2)

    def __init__(self, lost: set[int]) -> None:
        self.lost, self.reads = lost, 0

    def read_present(self) -> list[ServoReading]:
        self.reads += 1
        if self.reads in self.lost:
            raise BusFault("shoulder_lift stopped answering (no reply within 50 ms)")
        position = 2000 + 10 * self.reads
        return [ServoReading(position, 0, 0, 12.0, 30, 0, False) for _ in self.ids]


def test_range_recording_reads_again_after_a_lost_reply_and_ends_after_three_in_a_row() -> None:
    bus = _FlakyBus(lost={2, 3})
    ranges = arm_calibration.record_ranges(bus, lambda: bus.reads >= 5)  # type: ignore[arg-type]
    assert ranges == {1: (2010, 2050), 2: (2010, 2050)}  # reads 1, 4 and 5 counted
    bus = _FlakyBus(lost={2, 3, 4})
    with pytest.raises(BusFault, match="stopped answering"):
        arm_calibration.record_ranges(bus, lambda: False)  # type: ignore[arg-type]
    assert bus.reads == 4


def test_interactive_calibration_records_the_ranges_the_hand_moved_through(
    so101: LoadedRobot, tmp_path: Path
) -> None:
    file = tmp_path / "arm.json"
    with EmulatedBus(so101, seed=11) as bus:
        process = openral(
            "robot", "calibrate", "so101", "--transport", bus.path, "--calibration", str(file),
            stdin=subprocess.PIPE,
        )  # fmt: skip
        _enter(process)  # the arm is in the middle (EmulatedBus put it there)
        time.sleep(1.5)
        _sweep(bus, so101, pause_s=0.1)
        _enter(process)
        out, err = process.communicate(timeout=60)
        assert process.returncode == 0, err
        servo_limits = {
            i: (s.get("Min_Position_Limit"), s.get("Max_Position_Limit"))
            for i, s in bus.emulator.servos.items()
        }
    found = read_calibration(file, so101.description, so101.tables.real.feetech)  # type: ignore[arg-type]
    for joint, (low, high) in _limits(so101).items():
        motor = found[joint]
        assert motor.range_min < 2047 < motor.range_max, joint  # homed inside its range
        half = (high - low) / 2 * PER_RAD  # homed in the middle of the limits
        assert motor.range_min == pytest.approx(2047 - half, abs=3), joint
        if joint != "elbow_flex":  # the elbow folds onto the upper arm before its limit
            assert motor.range_max == pytest.approx(2047 + half, abs=3), joint
        assert servo_limits[motor.id] == (motor.range_min, motor.range_max)  # written to EEPROM
    assert f"written to {file}" in out.replace("\n", "")


def _lerobot_way(rig: Rig) -> dict[str, MotorCalibration]:
    """The steps of LeRobot's so101_follower calibration, on the same bus: homed in the
    middle, every joint swept by hand while its lowest and highest positions are recorded,
    wrist_roll given the whole turn (LeRobot's full-turn motor), written to the servos."""
    wiring = rig.robot.tables.real.feetech  # type: ignore[union-attr]
    bus = open_bus(rig.robot, rig.path)
    try:
        offsets = arm_calibration.record_homing(bus)
        low: dict[int, int] = {}
        high: dict[int, int] = {}
        for joint, (lo, hi) in _limits(rig.robot).items():
            for angle in (lo, hi, (lo + hi) / 2):
                rig.bus.arm.place(joint, angle)
                for servo_id, reading in zip(bus.ids, bus.read_present(), strict=True):
                    low[servo_id] = min(low.get(servo_id, 4095), reading.position)
                    high[servo_id] = max(high.get(servo_id, 0), reading.position)
        full_turn = next(m.id for m in wiring.motors if m.joint == "wrist_roll")
        low[full_turn], high[full_turn] = 0, 4095
        ranges = {i: (low[i], high[i]) for i in bus.ids}
        calibration = arm_calibration.calibration_of(wiring, offsets, ranges)
        arm_calibration.apply_calibration(bus, calibration)
    finally:
        bus.close()
    return calibration


def _radians_at(rig: Rig, file: Path, pose: dict[str, float]) -> list[float]:
    for joint, angle in pose.items():
        rig.bus.arm.place(joint, angle)
    hal = FeetechHal(rig.robot, rig.path, RealOptions(calibration_file=file))
    hal.connect()
    try:
        return [float(v) for v in hal.measured_angles()]
    finally:
        hal.disconnect()


@pytest.mark.exclusive  # the emulated shafts settle under gravity in real time between reads
def test_a_lerobot_calibration_gives_the_same_radians_as_the_drivers_own(
    rig: Rig, tmp_path: Path
) -> None:
    poses = [
        {"shoulder_pan": 0.7, "shoulder_lift": -0.9, "elbow_flex": 1.2, "wrist_roll": -1.5},
        {"shoulder_pan": -1.1, "wrist_flex": 1.0, "wrist_roll": 2.0, "gripper": 1.2},
    ]
    ours = [_radians_at(rig, rig.calibration, pose) for pose in poses]
    rig.bus.arm.place("shoulder_pan", 0.0)
    for joint, (low, high) in _limits(rig.robot).items():
        rig.bus.arm.place(joint, (low + high) / 2)
    lerobot_file = tmp_path / "lerobot.json"
    write_calibration(lerobot_file, _lerobot_way(rig))
    assert json.loads(lerobot_file.read_text())["wrist_roll"]["range_max"] == 4095
    theirs = [_radians_at(rig, lerobot_file, pose) for pose in poses]
    for mine, lerobot in zip(ours, theirs, strict=True):
        assert mine == pytest.approx(lerobot, abs=2 / PER_RAD)  # two steps
