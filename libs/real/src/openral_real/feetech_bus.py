"""A Feetech STS bus through feetech-servo-sdk (``scservo_sdk``), the SDK LeRobot uses.

What the driver asks of the bus: open the port (exclusively), ping every motor and check
its model, read and write single registers, read every motor's present block in one Sync
Read, and write every goal in one Sync Write. Every failure names the motor (bus id and
joint) and what went wrong, in one line.

Where the SDK falls short, and what is done here instead (with its own calls):

- ``GroupSyncRead.rxPacket`` drops each status packet's error byte (a servo's overload or
  over-temperature report is lost) and stops at the first motor that fails, leaving the
  older data of the motors after it in place: the Sync Read is sent with
  ``PacketHandler.syncReadTx`` and each motor's reply taken with ``readRx``, which keeps
  the error byte and says which motor failed;
- its reply timeout is the wire time plus 34 ms (twice a 16 ms USB latency timer, plus
  2), longer than two 100 Hz control periods, so a silent motor would be noticed late: each
  reply gets the manifest's ``reply_timeout_ms`` beyond its wire time
  (``setPacketTimeoutMillis``);
- it opens the port with a read timeout of 0 and polls it in a busy loop while waiting for
  a reply (a core at 100 % for the wait): the port here has a 1 ms read timeout, so the
  same loop sleeps in ``select`` until bytes arrive;
- it opens the port non-exclusively: a second program could write to the same bus; here
  the port is locked (``exclusive``), and a busy port is refused in one line;
- it times replies with the wall clock (``time.time``), which can step while a reply is
  awaited; here the port's clock is the monotonic one;
- it drains the port's output before every packet (``tcdrain``) and writes without a time
  limit: on a busy machine a write held the driver's loop for a third of a second; here a
  packet is written as it comes, and only a port that takes nothing for
  :data:`~openral_real.feetech_port.WRITE_TIMEOUT_S` is a timeout (pyserial's write times
  out too when the bytes went through but the thread got Python's lock back late).
  The port is :class:`~openral_real.feetech_port.ExclusivePort`.
"""

from __future__ import annotations

import contextlib
import termios
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import scservo_sdk as scs
import serial
from openral_core.real_wiring import FeetechWiring
from openral_core.servo_models import fault_text

from openral_real.errors import BusError, BusFault
from openral_real.feetech_port import ExclusivePort

PRESENT_FIRST = "Present_Position"
PRESENT_LAST = "Moving"
STALL_MS = 2.0
"""A reply wait this much longer than its timeout was this thread held up [ms]."""
CONNECT_TIMEOUT_MS = 50.0
"""Reply timeout of the pings and single-register reads and writes [ms]; each is asked up
to :data:`CONNECT_TRIES` times before the motor counts as silent (idempotent requests; a
busy host once missed one 50 ms wait on the emulator)."""
CONNECT_TRIES = 3


@dataclass(frozen=True)
class ServoReading:
    """One motor's present block, decoded."""

    position: int
    """Present_Position [steps], in the servo's own (homing-offset) frame."""
    velocity: int
    """[steps/s]"""
    load: int
    """[0.1 % of stall torque], signed."""
    voltage_v: float
    temperature_c: int
    faults: int
    """The status packet's error byte and the Status register, or-ed."""
    moving: bool


class FeetechBus:
    """One robot's Feetech bus on one serial port (see the module doc)."""

    def __init__(
        self,
        port: str,
        wiring: FeetechWiring,
        joints: Sequence[str],
        reply_timeout_s: float | None = None,
    ) -> None:
        """Nothing is opened until :meth:`open`.

        Args:
            port: The serial port (``/dev/ttyACM0``, an emulator's ``/dev/pts/N``).
            wiring: The robot's bus table.
            joints: The joint of each motor, in the wiring's order (for messages).
            reply_timeout_s: How long a present-block reply may take [s] (default: the
                manifest's ``reply_timeout_ms``, the control loop's; calibration, which has
                no loop to keep, waits longer).
        """
        self.port_name, self.wiring = port, wiring
        self.reply_timeout_s = (
            wiring.reply_timeout_s if reply_timeout_s is None else float(reply_timeout_s)
        )
        self.ids = wiring.ids
        self.names = {
            motor.id: f"motor {motor.id} ({joint})"
            for motor, joint in zip(wiring.motors, joints, strict=True)
        }
        self._port: Any = None
        self._packets: Any = None
        self._dirty = False
        self._goals: Any = None
        first, _ = wiring.registers[PRESENT_FIRST]
        last, size = wiring.registers[PRESENT_LAST]
        self._present = (first, last + size - first)
        self._byte_ms = 10_000.0 / wiring.baud_rate

    # -- opening -----------------------------------------------------------------------------

    def open(self) -> None:
        """Open the port at the wiring's baud rate, exclusively.

        Raises:
            BusError: No such port, no permission, or another program holds it.
        """
        port = ExclusivePort(self.port_name)
        port.baudrate = self.wiring.baud_rate
        try:
            port.setBaudRate(self.wiring.baud_rate)
        except serial.SerialException as error:
            raise BusError(_open_failure(self.port_name, error)) from None
        self._port, self._packets = port, scs.PacketHandler(self.wiring.protocol)
        address, size = self.wiring.registers["Goal_Position"]
        self._goals = scs.GroupSyncWrite(port, self._packets, address, size)
        for servo_id in self.ids:
            self._goals.addParam(servo_id, [0] * size)

    def close(self) -> None:
        """Close the port (idempotent)."""
        port, self._port = self._port, None
        if port is not None and port.is_open:
            with contextlib.suppress(OSError, serial.SerialException):
                port.closePort()

    def check_motors(self) -> None:
        """Ping every motor and check its model number.

        Raises:
            BusError: A motor does not answer or is another model (every one is named).
        """
        problems = []
        for servo_id in self.ids:
            model, result, _ = self._asked(self._packets.ping, self._port, servo_id)
            if result != scs.COMM_SUCCESS:
                problems.append(f"{self.names[servo_id]} does not answer")
            elif model != self.wiring.model_number:
                problems.append(
                    f"{self.names[servo_id]} is model {model}, not {self.wiring.servo_model} "
                    f"({self.wiring.model_number})"
                )
        if problems:
            raise BusError(
                f"{self.port_name} at {self.wiring.baud_rate} baud: {'; '.join(problems)}; check "
                "the cables, the power and the ids (nothing was written to the bus)"
            )

    # -- registers ---------------------------------------------------------------------------

    def read(self, name: str, servo_id: int) -> int:
        """Register ``name`` of one motor (signed where the servo model says so).

        Raises:
            BusFault: No reply, a corrupt one, or the port failed.
        """
        address, size = self.wiring.registers[name]
        data, result, error = self._asked(
            self._packets.readTxRx, self._port, servo_id, address, size
        )
        self._check(servo_id, result, error, f"reading {name}")
        return self._decode(name, int.from_bytes(bytes(data[:size]), "little"))

    def write(self, name: str, servo_id: int, value: int) -> None:
        """Write register ``name`` of one motor and wait for its acknowledgement.

        Raises:
            BusFault: No acknowledgement, a corrupt one, or the port failed.
        """
        address, size = self.wiring.registers[name]
        data = list(self._encode(name, value).to_bytes(size, "little"))
        result, error = self._asked(
            self._packets.writeTxRx, self._port, servo_id, address, size, data
        )
        self._check(servo_id, result, error, f"writing {name}")

    def write_all(self, name: str, values: Sequence[int]) -> None:
        """One Sync Write of register ``name``, a value per motor in wiring order (no reply).

        Raises:
            BusFault: The port failed.
        """
        address, size = self.wiring.registers[name]
        group = scs.GroupSyncWrite(self._port, self._packets, address, size)
        for servo_id, value in zip(self.ids, values, strict=True):
            group.addParam(servo_id, list(self._encode(name, value).to_bytes(size, "little")))
        self._check(None, self._call(group.txPacket), 0, f"writing {name}")

    def write_goals(self, steps: Sequence[int]) -> None:
        """One Sync Write of every Goal_Position [steps, the servos' own frame].

        Raises:
            BusFault: The port failed.
        """
        for servo_id, value in zip(self.ids, steps, strict=True):
            self._goals.changeParam(servo_id, [value & 0xFF, (value >> 8) & 0xFF])
        self._check(None, self._call(self._goals.txPacket), 0, "writing Goal_Position")

    # -- the present block -------------------------------------------------------------------

    def read_present(self) -> list[ServoReading]:
        """Every motor's present block in one Sync Read. A corrupt reply, or one missed while
        this thread was held up, is asked for again on its own, and so are the motors after
        it (their replies are flushed with it).

        Raises:
            BusFault: A motor did not answer, answered corrupt twice, or the port failed.
        """
        address, length = self._present
        ids = list(self.ids)
        if self._dirty:  # late replies of a failed read would be taken for this one's
            self._call(self._port.ser.reset_input_buffer)
            self._dirty = False
        result = self._call(self._packets.syncReadTx, self._port, address, length, ids, len(ids))
        self._check(None, result, 0, "sending the Sync Read")
        readings, alone = [], False
        for servo_id in ids:
            if not alone:
                data, result, error, alone = self._receive(servo_id, length)
            if alone:  # asked again; the Sync Read's replies still to come are flushed
                data, result, error = self._alone(servo_id, length)
            self._dirty = result != scs.COMM_SUCCESS
            self._check(servo_id, result, 0, "reading its present state")
            readings.append(self._reading(bytes(data[:length]), error))
        return readings

    # -- internals ---------------------------------------------------------------------------

    def _receive(self, servo_id: int, length: int) -> tuple[list[int], int, int, bool]:
        """One motor's reply to the Sync Read, and whether to ask it again on its own: a
        corrupt reply, or a failure when the wait took far longer than the timeout itself
        (this thread was held up by Python's lock or the scheduler while the reply came and
        went by)."""
        reply_ms = self._reply_ms(length)
        began = time.monotonic()
        self._port.setPacketTimeoutMillis(reply_ms)
        data, result, error = self._call(self._packets.readRx, self._port, servo_id, length)
        held_up = (time.monotonic() - began) * 1000.0 > reply_ms + STALL_MS
        again = result == scs.COMM_RX_CORRUPT or (result != scs.COMM_SUCCESS and held_up)
        return data, result, error, again

    def _alone(self, servo_id: int, length: int) -> tuple[list[int], int, int]:
        """Ask one motor for its present block on its own, once. The port's input is
        flushed first: the Sync Read's replies of the motors after it (the SDK would wade
        through them, and take none as this one's) are then asked for alone as well."""
        self._call(self._port.ser.reset_input_buffer)
        self._port.setPacketTimeoutMillis(self._reply_ms(length) + self._byte_ms * 8)
        address = self._present[0]
        data, result, error = self._call(
            self._packets.readTxRx, self._port, servo_id, address, length
        )
        return data, result, error

    def _reading(self, block: bytes, error: int) -> ServoReading:
        first = self._present[0]

        def field(name: str) -> int:
            address, size = self.wiring.registers[name]
            raw = int.from_bytes(block[address - first : address - first + size], "little")
            return self._decode(name, raw)

        return ServoReading(
            position=field("Present_Position"),
            velocity=field("Present_Velocity"),
            load=field("Present_Load"),
            voltage_v=field("Present_Voltage") / 10.0,
            temperature_c=field("Present_Temperature"),
            faults=(error | field("Status")) & 0x7F,
            moving=bool(field("Moving")),
        )

    def _reply_ms(self, length: int) -> float:
        """Wire time of one status packet of ``length`` data bytes plus the reply timeout."""
        return (6 + length) * self._byte_ms + self.reply_timeout_s * 1000.0

    def _asked(self, function: Any, *args: Any) -> Any:
        """A request to motor ``args[1]`` with a reply (the SDK's ``(..., result, error)``),
        sent again while it times out, up to :data:`CONNECT_TRIES` times. Before a retry a
        late reply gets one more timeout to arrive and is flushed; one the SDK still takes
        for another request's (it then indexes past its data) counts as a failed try."""
        reply: Any = None
        for _ in range(CONNECT_TRIES):
            self._port.setPacketTimeoutMillis(CONNECT_TIMEOUT_MS)
            try:
                reply = self._call(function, *args)
            except IndexError:  # the SDK read a late reply of another shape as this one's
                reply = None
            if reply is not None and reply[-2] != scs.COMM_RX_TIMEOUT:
                return reply
            time.sleep(CONNECT_TIMEOUT_MS / 1000.0)
            self._call(self._port.ser.reset_input_buffer)
        if reply is None:
            who = self.names.get(args[1], "the bus")
            raise BusFault(f"{who} answered out of turn {CONNECT_TRIES} times (late replies)")
        return reply

    def _call(self, function: Any, *args: Any) -> Any:
        """An SDK call; a port that failed (unplugged) becomes a :class:`BusFault`."""
        try:
            return function(*args)
        except (OSError, serial.SerialException, termios.error) as error:
            if self._port is not None:
                self._port.is_using = False
            raise BusFault(f"the bus on {self.port_name} failed: {error}") from None

    def _check(self, servo_id: int | None, result: int, error: int, doing: str) -> None:
        who = self.names.get(servo_id, "the bus") if servo_id is not None else "the bus"
        if result == scs.COMM_RX_TIMEOUT:
            raise BusFault(
                f"{who} stopped answering ({doing}: no reply within "
                f"{self.reply_timeout_s * 1000:g} ms)"
            )
        if result == scs.COMM_RX_CORRUPT:
            raise BusFault(f"{who} sent a corrupt reply ({doing}: bad checksum or cut short)")
        if result != scs.COMM_SUCCESS:
            raise BusFault(f"{who}: {doing} failed ({self._packets.getTxRxResult(result)})")
        if error:
            raise BusFault(f"{who} reports {fault_text(error)} ({doing})")

    def _decode(self, name: str, raw: int) -> int:
        bit = self.wiring.sign_bits.get(name)
        if bit is None:
            return raw
        magnitude = raw & ((1 << bit) - 1)
        return -magnitude if raw & (1 << bit) else magnitude

    def _encode(self, name: str, value: int) -> int:
        bit = self.wiring.sign_bits.get(name)
        if bit is None or value >= 0:
            return int(value)
        return min(-int(value), (1 << bit) - 1) | (1 << bit)


def _open_failure(port: str, error: serial.SerialException) -> str:
    text = str(error)
    if "No such file" in text or "Errno 2" in text:
        hint = "plug the bus adapter in, or start an emulator (openral sim bus ROBOT)"
        return f"{port}: no such serial port; {hint}"
    if "exclusively lock" in text or "Errno 11" in text:
        holder = "a driver, LeRobot, an emulator's client"
        return f"{port}: the port is busy (another program holds it open: {holder}); close it"
    if "Permission denied" in text or "Errno 13" in text:
        fix = "sudo usermod -aG dialout $USER, then log in again"
        return f"{port}: no permission to open the port; join the dialout group ({fix})"
    return f"{port}: cannot open the port ({text})"
