"""Fixtures of the real-robot tests: an emulated SO-101 bus, calibrated as a user would."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from openral_core import LoadedRobot, open_robot_by_id
from openral_core.tables import robot_tables
from openral_hal.factory import RealOptions
from openral_real import arm_calibration
from openral_real.calibration import MotorCalibration, write_calibration
from openral_real.emulator.emulated_bus import EmulatedBus
from openral_real.feetech_bus import FeetechBus
from openral_real.feetech_hal import FeetechHal


@dataclass
class Rig:
    """An emulated arm on its bus, and the file it was calibrated into."""

    robot: LoadedRobot
    bus: EmulatedBus
    calibration: Path

    @property
    def path(self) -> str:
        return self.bus.path

    def hal(self) -> FeetechHal:
        """A HAL for this bus (not connected) that collects its fault lines."""
        hal = FeetechHal(self.robot, self.path, RealOptions(calibration_file=self.calibration))
        hal.on_fault = self.faults.append
        return hal

    def __post_init__(self) -> None:
        self.faults: list[str] = []


def open_bus(robot: LoadedRobot, path: str) -> FeetechBus:
    """The robot's bus on ``path``, opened (the caller closes it)."""
    bus = FeetechBus(path, robot.tables.real.feetech, [j.name for j in robot.description.joints])  # type: ignore[union-attr]
    bus.open()
    return bus


def calibrate(robot: LoadedRobot, path: str, file: Path) -> dict[str, MotorCalibration]:
    """`robot calibrate --non-interactive` in code: home where the arm is, ranges from the
    manifest's limits, written to the servos and to ``file``."""
    wiring = robot.tables.real.feetech  # type: ignore[union-attr]
    bus = open_bus(robot, path)
    try:
        offsets = arm_calibration.record_homing(bus)
        ranges = arm_calibration.ranges_from_limits(robot.description, wiring)
        calibration = arm_calibration.calibration_of(wiring, offsets, ranges)
        arm_calibration.apply_calibration(bus, calibration)
    finally:
        bus.close()
    write_calibration(file, calibration)
    return calibration


BESIDE_OTHERS_RATE_HZ = 10.0
BESIDE_OTHERS_REPLY_MS = 100.0


def beside_others(robot: LoadedRobot) -> LoadedRobot:
    """``robot`` with a real driver slow enough to run beside other tests: 10 Hz, 100 ms for a
    reply. The emulator shares the test's process and, with three workers on two cores, is
    held up for tens of milliseconds at times (CI saw a reply 30 ms late): a control period
    and a reply timeout of 100 ms ride that out. The manifest's own 100 Hz and 6 ms are what
    the exclusive tests measure."""
    real = robot.description.real
    assert real is not None and real.feetech is not None
    feetech = real.feetech.model_copy(update={"reply_timeout_ms": BESIDE_OTHERS_REPLY_MS})
    relaxed = real.model_copy(update={"control_rate_hz": BESIDE_OTHERS_RATE_HZ, "feetech": feetech})
    description = robot.description.model_copy(update={"real": relaxed})
    return LoadedRobot(description, robot.folder, robot_tables(description))


@pytest.fixture
def so101() -> LoadedRobot:
    """The SO-101 for tests beside others (:func:`beside_others`); a module measuring real
    time overrides this fixture with the manifest as it ships."""
    return beside_others(open_robot_by_id("so101"))


@pytest.fixture
def rig(so101: LoadedRobot, tmp_path: Path) -> Iterator[Rig]:
    """An emulated SO-101 at the middle of its ranges, calibrated into ``tmp_path``."""
    with EmulatedBus(so101, seed=7) as bus:
        file = tmp_path / "so101.json"
        calibrate(so101, bus.path, file)
        yield Rig(so101, bus, file)
