"""The real driver's control tick on the emulated bus: bus round trips and lateness.

An SO-101 bus is emulated by ``openral sim bus`` in a process of its own (its replies leave
when a 1 Mbaud wire would carry them), calibrated non-interactively, and driven by the
Feetech HAL at 100 Hz for ``--seconds`` while a client aims it at a new sine target every
cycle. Measured in the same run:

- **bare SDK**: the round trip of the SDK's own ``GroupSyncRead`` of the same present block
  plus a ``GroupSyncWrite`` of six goals, back to back, on the servos as the driver set
  them up (return delay 0): what the SDK alone does on this bus;
- **wire**: the bytes of the Sync Read and its replies at the baud rate (10 bits a byte),
  a floor no driver goes under (the Sync Write has no reply to wait for);
- **driver**: each cycle's Sync Read plus Sync Write, and how late each cycle started
  after its due time (the line: no late tick over 5 ms).

Writes ``benchmarks/results/real_bus.json``. The numbers are on the emulator, not on
hardware.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scservo_sdk as scs
from openral_core import open_robot_by_id
from openral_hal.factory import RealOptions
from openral_real.feetech_hal import FeetechHal
from rich.console import Console
from rich.table import Table

from benchmarks.results_file import write_results

OPENRAL = Path(sys.executable).parent / "openral"
LATE_LIMIT_S = 0.005
"""The issue's line: no control tick later than this [s]."""


def start_emulator(folder: Path) -> tuple[subprocess.Popen[str], str]:
    """``openral sim bus so101`` in a process of its own, and its port."""
    process = subprocess.Popen(
        [str(OPENRAL), "sim", "bus", "so101", "--log", str(folder / "bus.log")],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None
    return process, process.stdout.readline().strip()


def calibrate(port: str, file: Path) -> None:
    subprocess.run(
        [str(OPENRAL), "robot", "calibrate", "so101", "--transport", port,
         "--non-interactive", "--calibration", str(file)],
        check=True, capture_output=True,
    )  # fmt: skip


def bare_sdk(port: str, cycles: int) -> list[float]:
    """Round trips [s] of the SDK's group Sync Read (present block) + Sync Write (goals)."""
    handler_port, packets = scs.PortHandler(port), scs.PacketHandler(0)
    handler_port.openPort()
    handler_port.setBaudRate(1_000_000)
    ids = [1, 2, 3, 4, 5, 6]
    reader = scs.GroupSyncRead(handler_port, packets, 56, 11)
    writer = scs.GroupSyncWrite(handler_port, packets, 42, 2)
    for servo_id in ids:
        reader.addParam(servo_id)
    times = []
    for _ in range(cycles):
        started = time.perf_counter()
        reader.txRxPacket()
        for servo_id in ids:
            goal = reader.getData(servo_id, 56, 2)
            writer.addParam(servo_id, [goal & 0xFF, goal >> 8])
        writer.txPacket()
        writer.clearParam()
        times.append(time.perf_counter() - started)
    handler_port.closePort()
    return times


def wire_s(baud: int) -> float:
    """Bytes of one Sync Read of 11 bytes from 6 servos (request and replies) at ``baud``
    (10 bits a byte) [s]: what a host waits for. The Sync Write has no reply: a host hands
    its 26 bytes to the adapter and goes on."""
    return ((8 + 6) + 6 * (6 + 11)) * 10 / baud


def drive(port: str, file: Path, seconds: float) -> FeetechHal:
    """The HAL at 100 Hz for ``seconds``, aimed at a sine every cycle."""
    hal = FeetechHal(open_robot_by_id("so101"), port, RealOptions(calibration_file=file))
    hal.connect()
    hold = hal.hold_action()
    started = time.monotonic()
    while (now := time.monotonic() - started) < seconds:
        target = hold.copy()
        target[:4] += 0.4 * math.sin(2 * math.pi * now / 3.0)
        hal.send_action(target)
        time.sleep(0.01)
    assert not hal.estopped, hal.estop_reason
    return hal


def summary(times_s: list[float]) -> dict[str, float]:
    values = np.array(times_s) * 1e3
    return {
        "median_ms": float(np.median(values)),
        "p99_ms": float(np.percentile(values, 99)),
        "max_ms": float(values.max()),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=60.0, help="how long the HAL runs")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        emulator, port = start_emulator(folder)
        try:
            calibrate(port, folder / "arm.json")
            try:
                hal = drive(port, folder / "arm.json", args.seconds)
            finally:
                late = [
                    line for line in (folder / "bus.log").read_text().splitlines() if "LATE" in line
                ]
                print(f"emulator replies late: {len(late)}", *late[:5], sep="\n")
            times = hal.times
            driver = summary(list(times.round_trip_s))
            late = list(times.late_s)
            cycles = times.cycles
            hal.disconnect()
            bare = summary(bare_sdk(port, 2000))  # the servos as the driver set them up
        finally:
            emulator.communicate("quit\n", timeout=30)
    lateness = {**summary(late), "over_5_ms": float(sum(x > LATE_LIMIT_S for x in late))}
    wire_ms = wire_s(1_000_000) * 1e3
    results = {
        "seconds": args.seconds,
        "cycles": cycles,
        "rate_hz": cycles / args.seconds,
        "wire_ms": wire_ms,
        "bare_sdk": bare,
        "driver": driver,
        "late": lateness,
        "cpus": os.cpu_count(),
    }
    table = Table(title=f"Feetech bus, so101 on the emulator, 100 Hz for {args.seconds:g} s")
    for column in ("measure", "median ms", "p99 ms", "max ms"):
        table.add_column(column, justify="left" if column == "measure" else "right")
    table.add_row("Sync Read on the wire at 1 Mbaud (floor)", f"{wire_ms:.2f}", "", "")
    rows = (
        ("bare SDK read+write", bare),
        ("driver tick read+write", driver),
        ("tick start lateness", lateness),
    )
    for name, row in rows:
        table.add_row(name, *(f"{row[k]:.2f}" for k in ("median_ms", "p99_ms", "max_ms")))
    Console(width=120).print(table)
    print(
        f"{cycles} cycles ({cycles / args.seconds:.1f} Hz); ticks later than 5 ms: "
        f"{lateness['over_5_ms']:.0f}; driver / bare SDK median: "
        f"{driver['median_ms'] / bare['median_ms']:.2f}x; driver / wire median: "
        f"{driver['median_ms'] / wire_ms:.2f}x"
    )
    print(f"wrote {write_results('real_bus', results)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
