"""``openral sim bus``: a robot's Feetech servo bus, emulated on a pseudo-terminal.

Example::

    openral sim bus so101 --log out/bus.log
    /dev/pts/4
    ...
    openral deploy real --robot so101 --transport /dev/pts/4      # in a second terminal

The first line printed is the port's path, alone, for scripts. The servos answer the STS
protocol byte for byte at the manifest's baud rate (wire times included) and their shafts
move the robot's simulation (alone, or in ``--scene``), so the real driver, a policy and a
ROS stack can be rehearsed before the arm is plugged in. Faults are injected by typing
commands (``help`` lists them): ``silent 3``, ``checksum 1``, ``overload gripper``,
``unplug``, ``replug``, ``clear``, ``move shoulder_pan 0.5``, ``status``. It serves until
Ctrl-C, SIGTERM or ``quit``; the end of its input alone does not stop it.
"""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:
    from openral_real.emulator.emulated_bus import EmulatedBus

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def bus(
    robot_id: Annotated[str, typer.Argument(help="Robot id with a feetech bus (so100, so101).")],
    scene: Annotated[
        Path | None,
        typer.Option("--scene", help="Simulate the arm in this deploy scene (default: alone)."),
    ] = None,
    log: Annotated[
        Path | None,
        typer.Option("--log", help="Write one line per packet and event to this file."),
    ] = None,
    link: Annotated[
        Path | None,
        typer.Option("--link", help="Keep a symlink here to the current port (kept on replug)."),
    ] = None,
    seed: Annotated[
        int, typer.Option("--seed", min=0, help="Where the servo horns sit on their shafts.")
    ] = 0,
) -> None:
    """Serve ROBOT_ID's servo bus on a pseudo-terminal; print its path first."""
    from openral_core import open_robot_by_id
    from openral_core.loader import load_scene
    from openral_hal.realtime import ahead_of_other_programs
    from openral_real.emulator.emulated_bus import EmulatedBus

    robot = open_robot_by_id(robot_id)
    loaded_scene = load_scene(scene) if scene is not None else None
    for path in (log, link):
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
    log_file = log.open("w", encoding="utf-8") if log is not None else None
    try:
        emulated = EmulatedBus(robot, scene=loaded_scene, seed=seed, log=log_file, link=link)
        with ahead_of_other_programs():  # servos answer whatever else runs
            _serve(emulated)
    finally:
        if log_file is not None:
            log_file.close()


def _serve(emulated: EmulatedBus) -> None:
    """Print the path, then obey the console until a signal or ``quit``."""
    stop = threading.Event()
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in STOP_SIGNALS}
    path = emulated.start()
    try:
        print(path, flush=True)
        wiring = emulated.wiring
        print(
            f"{emulated.robot.name}: {len(wiring.motors)} emulated {wiring.servo_model} servos "
            f"(ids {', '.join(str(i) for i in wiring.ids)}) at {wiring.baud_rate} baud; type "
            "help for the fault commands; Ctrl-C stops",
            flush=True,
        )
        reader = threading.Thread(target=_console, args=(emulated, stop))
        reader.daemon = True
        reader.start()
        stop.wait()
    finally:
        emulated.stop()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    print("bus stopped", flush=True)


def _console(emulated: EmulatedBus, stop: threading.Event) -> None:
    """Read commands from stdin until ``quit`` (its end leaves the bus serving)."""
    from openral_real.emulator.bus_console import ConsoleError, obey

    for line in sys.stdin:
        if line.strip() in ("quit", "exit"):
            stop.set()
            return
        try:
            reply = obey(line, emulated)
        except ConsoleError as problem:
            reply = f"error: {problem}"
        if reply:
            print(reply, flush=True)
