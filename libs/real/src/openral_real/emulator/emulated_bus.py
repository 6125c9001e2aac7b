"""One robot's emulated bus, whole: simulation, servos, pseudo-terminal, log.

:class:`EmulatedBus` builds what ``openral sim bus`` serves: the robot simulated alone (or
in a scene), its arm put in the middle of every joint's range (where an arm is calibrated),
one emulated servo per motor of the manifest's bus, on a pseudo-terminal a driver opens as
its serial port. Its log has one line per packet and event, stamped with the system clock.
"""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path
from types import TracebackType
from typing import TextIO

from openral_core.loaded import LoadedRobot
from openral_core.models import DeployScene, LimitedJoint
from openral_core.servo_models import SERVO_MODELS
from openral_hal.errors import ConfigurationError
from openral_hal.factory import build_hal
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.protocol import Tickable

from openral_real.emulator.bus_emulator import BusEmulator
from openral_real.emulator.emulated_arm import EmulatedArm, servo_held
from openral_real.emulator.pty_bus import PtyBus

SWITCH_INTERVAL_S = 0.0005
"""Longest time a thread holds Python's lock while another waits for it [s] (Python's
default, 5 ms, is most of the time the driver waits for a servo's reply)."""


class EmulatedBus:
    """A robot's servo bus emulated on a pseudo-terminal (see the module doc)."""

    def __init__(
        self,
        robot: LoadedRobot,
        *,
        scene: DeployScene | None = None,
        seed: int = 0,
        log: TextIO | None = None,
        link: Path | None = None,
        middle: bool = True,
    ) -> None:
        """Build and connect the simulation; nothing is served until :meth:`start`.

        Args:
            robot: A robot whose manifest has a feetech bus.
            scene: Simulate the robot in this scene instead of alone.
            seed: Draws where each servo's horn was mounted (its encoder's zero).
            log: Where the packet log goes (None: kept in :attr:`lines` only).
            link: A symlink kept pointing at the current pseudo-terminal.
            middle: Put the arm in the middle of every joint's range first (the robot
                alone only).

        Raises:
            ConfigurationError: The manifest has no feetech bus.
        """
        real = robot.tables.real
        if real is None or real.feetech is None:
            raise ConfigurationError(f"{robot.name} has no feetech bus (real.feetech) to emulate")
        self.robot, self.wiring = robot, real.feetech
        self.lines: list[str] = []
        self._log, self._log_lock = log, threading.Lock()
        hal = build_hal(robot if scene is not None else servo_held(robot), mode="sim", scene=scene)
        hal.connect()
        assert isinstance(hal, MujocoArmHAL | Tickable)
        self.hal = hal
        self.arm = EmulatedArm(hal, robot, SERVO_MODELS[self.wiring.servo_model], seed)
        if middle and isinstance(hal, MujocoArmHAL):
            for joint in robot.description.joints:
                if isinstance(joint, LimitedJoint):
                    self.arm.place(joint.name, sum(joint.position_limits) / 2.0)
        self.emulator = BusEmulator(self.arm, self.wiring, log=self.log, seed=seed)
        self.pty = PtyBus(self.emulator, link)
        self._switch_interval = sys.getswitchinterval()

    @property
    def path(self) -> str:
        """The pseudo-terminal's path while plugged in."""
        return self.pty.path

    def log(self, line: str) -> None:
        """One log line, stamped with the system clock [s]."""
        stamped = f"{time.time():.6f} {line}"
        with self._log_lock:
            self.lines.append(stamped)
            if self._log is not None:
                self._log.write(stamped + "\n")
                self._log.flush()

    def start(self) -> str:
        """Open the pseudo-terminal, start the simulation's clock and serve; the path.

        The process's thread switch interval drops to :data:`SWITCH_INTERVAL_S`, so the
        thread that answers the bus is never kept waiting for Python's lock by the
        simulation's thread for longer than a servo takes to answer."""
        self._switch_interval = sys.getswitchinterval()
        sys.setswitchinterval(min(self._switch_interval, SWITCH_INTERVAL_S))
        path = self.pty.open()
        self.arm.start()
        self.pty.start()
        self.log(f"SERVING {self.robot.name} on {path}")
        return path

    def stop(self) -> None:
        """Stop serving and the simulation (idempotent); the switch interval as it was."""
        self.pty.stop()
        self.arm.stop()
        self.hal.disconnect()
        sys.setswitchinterval(self._switch_interval)

    def written(self, register: str, after: float = 0.0) -> list[str]:
        """Log lines that wrote ``register`` (WRITE or SYNC_WRITE) after ``after`` [s]."""
        return [
            line
            for line in list(self.lines)
            if float(line.split(" ", 1)[0]) > after
            and (f"SYNC_WRITE {register} " in line or f" {register}=" in line)
        ]

    def __enter__(self) -> EmulatedBus:
        self.start()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self.stop()
