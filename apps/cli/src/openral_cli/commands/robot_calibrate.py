"""``openral robot calibrate``: record a Feetech arm's calibration, as LeRobot does.

Example::

    openral robot calibrate so101 --transport /dev/ttyACM0 --arm-id my_follower

Torque goes off and stays off. Move the arm to the middle of every joint's range and press
ENTER (each servo is homed there); move every joint through its whole travel and press
ENTER again (the ranges are recorded, shown live). The offsets and ranges are written to the
servos and to ``<arm id>.json`` in LeRobot's calibration folder (or ``--calibration``), in
LeRobot's format: LeRobot uses the file as it is, and so does ``openral deploy real``.

``--non-interactive`` takes the arm as it is for the middle and the manifest's position
limits as the ranges (for tests and emulators); ``--apply FILE`` writes an existing file's
calibration to the servos (an arm calibrated elsewhere) and nothing else.
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from openral_cli.console import out

CALIBRATION_REPLY_S = 0.2
"""How long calibration waits for a servo's reply [s]: it keeps no control loop's pace, so
a wait far beyond a servo's sub-millisecond answer costs nothing and rides out a busy host
(a calibration on the emulator once ended early under a loaded test run)."""

if TYPE_CHECKING:
    from openral_core import LoadedRobot
    from openral_real.calibration import MotorCalibration
    from openral_real.feetech_bus import FeetechBus


def calibrate(
    robot_id: Annotated[str, typer.Argument(help="Robot id with a feetech bus (so100, so101).")],
    transport: Annotated[
        str, typer.Option("--transport", help="The bus's serial port (/dev/ttyACM0, /dev/pts/N).")
    ],
    arm_id: Annotated[
        str | None,
        typer.Option("--arm-id", help="Which arm (LeRobot's --robot.id); default: the robot id."),
    ] = None,
    calibration: Annotated[
        Path | None,
        typer.Option("--calibration", help="Write the file here instead of LeRobot's folder."),
    ] = None,
    non_interactive: Annotated[
        bool,
        typer.Option(
            "--non-interactive",
            help="Home where the arm is now; ranges from the manifest's position limits.",
        ),
    ] = False,
    apply: Annotated[
        Path | None,
        typer.Option("--apply", help="Write this calibration file to the servos, nothing else."),
    ] = None,
) -> None:
    """Calibrate ROBOT_ID's arm on TRANSPORT and write LeRobot's calibration file."""
    from openral_core import open_robot_by_id
    from openral_hal.errors import ConfigurationError
    from openral_real.calibration import calibration_path, read_calibration
    from openral_real.feetech_bus import FeetechBus

    robot = open_robot_by_id(robot_id)
    wiring = robot.tables.real.feetech if robot.tables.real is not None else None
    if wiring is None:
        raise ConfigurationError(f"{robot_id} has no feetech bus in its manifest (real.feetech)")
    applied = read_calibration(apply, robot.description, wiring) if apply is not None else None
    target = calibration_path(robot_id, wiring, arm_id, calibration)
    joints = [joint.name for joint in robot.description.joints]
    bus = FeetechBus(transport, wiring, joints, reply_timeout_s=CALIBRATION_REPLY_S)
    bus.open()
    try:
        bus.check_motors()
        if applied is not None:
            _apply(bus, applied, apply)
            return
        found = _record(robot, bus, non_interactive)
        from openral_real.arm_calibration import apply_calibration

        apply_calibration(bus, found)
    finally:
        bus.close()
    from openral_real.calibration import write_calibration

    write_calibration(target, found)
    _show(found, f"calibration of {robot_id} written to {target}")


def _apply(bus: FeetechBus, calibration: dict[str, MotorCalibration], file: Path | None) -> None:
    from openral_real.arm_calibration import apply_calibration

    apply_calibration(bus, calibration)
    _show(calibration, f"{file} written to the servos (torque is off)")


def _record(
    robot: LoadedRobot, bus: FeetechBus, non_interactive: bool
) -> dict[str, MotorCalibration]:
    """Home the servos, then take the ranges (from the user's motion or the manifest)."""
    from openral_real import arm_calibration as steps

    wiring = bus.wiring
    steps.release(bus)
    if not non_interactive:
        typer.prompt(
            "Torque is off. Move the arm to the middle of every joint's range, then press ENTER",
            default="",
            show_default=False,
        )
    offsets = steps.record_homing(bus)
    if non_interactive:
        ranges = steps.ranges_from_limits(robot.description, wiring)
    else:
        ranges = _record_ranges(bus)
    return steps.calibration_of(wiring, offsets, ranges)


def _record_ranges(bus: FeetechBus) -> dict[int, tuple[int, int]]:
    """The ranges, recorded until ENTER, shown live."""
    from openral_real.arm_calibration import record_ranges
    from rich.live import Live
    from rich.table import Table

    finished = threading.Event()

    def wait_for_enter() -> None:
        typer.prompt(
            "Move every joint through its whole range, then press ENTER",
            default="",
            show_default=False,
        )
        finished.set()

    threading.Thread(target=wait_for_enter, daemon=True).start()
    with Live(auto_refresh=False, console=out.console) as live:

        def seen(now: dict[int, tuple[int, int, int]]) -> None:
            table = Table(title="ranges so far [steps]")
            for column in ("motor", "now", "lowest", "highest"):
                table.add_column(column, justify="right")
            for servo_id, (present, low, high) in now.items():
                table.add_row(bus.names[servo_id], str(present), str(low), str(high))
            live.update(table, refresh=True)

        return record_ranges(bus, finished.is_set, seen)


def _show(calibration: dict[str, MotorCalibration], title: str) -> None:
    from rich.table import Table

    table = Table(title=title)
    for column in ("joint", "id", "drive_mode", "homing_offset", "range_min", "range_max"):
        table.add_column(column, justify="right")
    for joint, motor in calibration.items():
        table.add_row(
            joint,
            str(motor.id),
            str(motor.drive_mode),
            str(motor.homing_offset),
            str(motor.range_min),
            str(motor.range_max),
        )
    out.print(table)
