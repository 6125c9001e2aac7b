"""The servos of one robot on one emulated Feetech bus: instruction packets in, replies out.

Each servo (:class:`~openral_real.emulator.servo_memory.ServoMemory`) answers at its id:
PING, READ, WRITE (a reply unless broadcast), REG_WRITE and ACTION, SYNC_WRITE (no
reply) and SYNC_READ (every listed servo replies in turn). A reply carries the servo's
fault bits in its error byte. Replies come with the time they end on the wire
(:class:`Reply`): the request's bytes, each servo's return delay (Return_Delay_Time x 2 µs)
and the reply's bytes at the bus's baud rate, 10 bits a byte, so a host sees a real bus's
round trips.

Faults can be injected (:meth:`BusEmulator.inject`): a servo that stops answering
(``silent``), one that reports ``overload``, ``overheat`` or ``voltage`` in every reply (an
overloaded servo also drops its torque, as an STS does), and a checksum storm
(:attr:`BusEmulator.corrupt_share` of the replies with a wrong checksum).
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

from openral_core.real_wiring import FeetechWiring
from openral_core.servo_models import SERVO_MODELS

from openral_real.emulator.emulated_arm import Drive, EmulatedArm
from openral_real.emulator.servo_memory import ServoMemory, from_sign_magnitude
from openral_real.emulator.sts_wire import BROADCAST_ID, Instruction, Packet, status_packet

BITS_PER_BYTE = 10
"""A start bit, 8 data bits and a stop bit."""
DELAY_UNIT_S = 2e-6
"""Return_Delay_Time's unit [s]."""
DRIVE_REGISTERS = frozenset(
    {"Torque_Enable", "Goal_Position", "Goal_Velocity", "Acceleration", "Homing_Offset"}
)


class Fault(StrEnum):
    """What can be wrong with one emulated servo."""

    SILENT = "silent"
    OVERLOAD = "overload"
    OVERHEAT = "overheat"
    VOLTAGE = "voltage"


FAULT_BITS = {Fault.VOLTAGE: 0x01, Fault.OVERHEAT: 0x04, Fault.OVERLOAD: 0x20}


@dataclass(frozen=True)
class Reply:
    """A status packet and when its last byte leaves the servo, counted from the moment the
    request's last byte arrived [s]."""

    at_s: float
    data: bytes


class BusEmulator:
    """Every servo of one robot's bus (see the module doc)."""

    def __init__(
        self,
        arm: EmulatedArm,
        wiring: FeetechWiring,
        log: Callable[[str], None] | None = None,
        seed: int = 0,
    ) -> None:
        """Servos fresh from the factory at the wiring's ids, driving ``arm``'s joints."""
        model = SERVO_MODELS[wiring.servo_model]
        self.arm, self.wiring, self.log = arm, wiring, log or (lambda _: None)
        self.servos = {motor.id: ServoMemory(model, motor.id) for motor in wiring.motors}
        self.joint_of = {motor.id: arm.joints.index(motor.joint) for motor in wiring.motors}
        self.byte_s = BITS_PER_BYTE / wiring.baud_rate
        self.faults: dict[int, set[Fault]] = {servo_id: set() for servo_id in self.servos}
        self.corrupt_share = 0.0
        """Share of replies sent with a wrong checksum (0 to 1)."""
        self.lost: dict[int, int] = {}
        """Servo id → how many of its next replies are lost on the wire (noise); the
        request itself is obeyed."""
        self.garbled: dict[int, int] = {}
        """Servo id → how many of its next replies arrive with a wrong checksum (noise)."""
        self._draw = random.Random(seed)
        self._registered: dict[int, tuple[int, bytes]] = {}
        self._names = {address: name for name, (address, _) in model.registers.items()}
        self._handlers = {
            int(Instruction.PING): self._ping,
            int(Instruction.READ): self._read,
            int(Instruction.WRITE): self._write,
            int(Instruction.REG_WRITE): self._reg_write,
            int(Instruction.ACTION): self._action,
            int(Instruction.SYNC_READ): self._sync_read,
            int(Instruction.SYNC_WRITE): self._sync_write,
        }

    # -- faults ------------------------------------------------------------------------------

    def inject(self, servo_id: int, fault: Fault) -> None:
        """Give servo ``servo_id`` ``fault`` (until :meth:`clear`)."""
        self.faults[servo_id].add(fault)
        if fault is Fault.OVERLOAD:
            self.servos[servo_id].set("Torque_Enable", 0)
            self._update_drive(servo_id)
        self.log(f"FAULT {fault.value} on servo {servo_id}")

    def clear(self) -> None:
        """Every fault and the checksum storm end."""
        for faults in self.faults.values():
            faults.clear()
        self.corrupt_share = 0.0
        self.log("FAULTS cleared")

    # -- packets -----------------------------------------------------------------------------

    def handle(self, packet: Packet, request_bytes: int) -> list[Reply]:
        """Obey one instruction packet; the replies the bus carries back, in order."""
        self.refresh()
        handler = self._handlers.get(packet.instruction)
        if handler is None:
            self.log(f"UNKNOWN instruction 0x{packet.instruction:02x} to {packet.servo_id}")
            return []
        answers = handler(packet)
        clock = request_bytes * self.byte_s
        replies = []
        for servo_id, params in answers:
            if self.lost.get(servo_id, 0) > 0:
                self.lost[servo_id] -= 1
                continue
            clock += self.servos[servo_id].get("Return_Delay_Time") * DELAY_UNIT_S
            data = self._status(servo_id, params)
            clock += len(data) * self.byte_s
            replies.append(Reply(clock, data))
        return replies

    def refresh(self) -> None:
        """Every servo's present registers from its shaft now."""
        shafts = self.arm.shafts()
        for servo_id, servo in self.servos.items():
            shaft = shafts[self.joint_of[servo_id]]
            resolution = self.wiring.resolution
            servo.set(
                "Present_Position", round(shaft.raw - servo.get("Homing_Offset")) % resolution
            )
            servo.set("Present_Velocity", round(shaft.speed))
            faults = self.faults[servo_id]
            load = 1.0 if Fault.OVERLOAD in faults else shaft.load
            servo.set("Present_Load", round(load * 1000))
            servo.set("Present_Voltage", 55 if Fault.VOLTAGE in faults else 120)
            servo.set("Present_Temperature", 78 if Fault.OVERHEAT in faults else 30)
            servo.set("Status", self._fault_bits(servo_id))
            goal = servo.get("Goal_Position")
            moving = abs(shaft.speed) > 20 or servo.get("Present_Position") != goal
            servo.set("Moving", int(moving and servo.get("Torque_Enable") == 1))

    # -- instructions (each returns the servos that answer and what they answer) -----------

    def _ping(self, packet: Packet) -> list[tuple[int, bytes]]:
        self.log(f"PING {packet.servo_id}")
        return [(i, b"") for i in self._addressed(packet.servo_id)]

    def _read(self, packet: Packet) -> list[tuple[int, bytes]]:
        if len(packet.params) != 2 or packet.servo_id == BROADCAST_ID:
            return []
        address, length = packet.params
        self.log(f"READ {packet.servo_id} {self._name(address)} x{length}")
        return [(i, self.servos[i].read(address, length)) for i in self._live(packet.servo_id)]

    def _write(self, packet: Packet) -> list[tuple[int, bytes]]:
        if not packet.params:
            return []
        address, payload = packet.params[0], packet.params[1:]
        targets = self._addressed(packet.servo_id)
        for servo_id in targets:
            self._store(servo_id, address, payload)
        self.log(f"WRITE {packet.servo_id} {self._values(address, payload)}")
        if packet.servo_id == BROADCAST_ID:
            return []
        return [(i, b"") for i in targets if self.servos[i].get("Response_Status_Level")]

    def _reg_write(self, packet: Packet) -> list[tuple[int, bytes]]:
        if not packet.params:
            return []
        for servo_id in self._addressed(packet.servo_id):
            self._registered[servo_id] = (packet.params[0], packet.params[1:])
        self.log(f"REG_WRITE {packet.servo_id} {self._values(packet.params[0], packet.params[1:])}")
        return [] if packet.servo_id == BROADCAST_ID else self._acks(packet.servo_id)

    def _action(self, packet: Packet) -> list[tuple[int, bytes]]:
        for servo_id in self._addressed(packet.servo_id):
            if servo_id in self._registered:
                self._store(servo_id, *self._registered.pop(servo_id))
        self.log(f"ACTION {packet.servo_id}")
        return [] if packet.servo_id == BROADCAST_ID else self._acks(packet.servo_id)

    def _sync_write(self, packet: Packet) -> list[tuple[int, bytes]]:
        if len(packet.params) < 2:
            return []
        address, length, body = packet.params[0], packet.params[1], packet.params[2:]
        entries = []
        for start in range(0, len(body) - length, length + 1):
            servo_id, payload = body[start], body[start + 1 : start + 1 + length]
            if len(payload) < length:
                break
            if servo_id in self.servos and Fault.SILENT not in self.faults[servo_id]:
                self._store(servo_id, address, payload)
            entries.append(f"{servo_id}={_number(payload)}")
        self.log(f"SYNC_WRITE {self._name(address)} {' '.join(entries)}")
        return []

    def _sync_read(self, packet: Packet) -> list[tuple[int, bytes]]:
        if len(packet.params) < 2:
            return []
        address, length, ids = packet.params[0], packet.params[1], packet.params[2:]
        self.log(f"SYNC_READ {self._name(address)} x{length} {' '.join(map(str, ids))}")
        return [(i, self.servos[i].read(address, length)) for i in ids if self._answers(i)]

    # -- internals ---------------------------------------------------------------------------

    def _store(self, servo_id: int, address: int, payload: bytes) -> None:
        shaft = self.arm.shafts()[self.joint_of[servo_id]]
        changed = self.servos[servo_id].write(address, payload, round(shaft.raw))
        if Fault.OVERLOAD in self.faults[servo_id]:
            self.servos[servo_id].set("Torque_Enable", 0)
        if DRIVE_REGISTERS.intersection(changed):
            self._update_drive(servo_id)

    def _update_drive(self, servo_id: int) -> None:
        servo = self.servos[servo_id]
        goal = (servo.get("Goal_Position") + servo.get("Homing_Offset")) % self.wiring.resolution
        speed = servo.get("Goal_Velocity")
        model = SERVO_MODELS[self.wiring.servo_model]
        drive = Drive(
            torque=servo.get("Torque_Enable") == 1,
            goal_raw=float(goal),
            max_speed=float(abs(speed)) if speed else model.max_speed_steps_s,
            acceleration=servo.get("Acceleration"),
        )
        self.arm.drive(self.joint_of[servo_id], drive)

    def _status(self, servo_id: int, params: bytes) -> bytes:
        data = status_packet(servo_id, self._fault_bits(servo_id), params)
        garbled = self.garbled.get(servo_id, 0) > 0
        if garbled:
            self.garbled[servo_id] -= 1
        if garbled or (self.corrupt_share and self._draw.random() < self.corrupt_share):
            data = data[:-1] + bytes([data[-1] ^ 0x5A])
        return data

    def _fault_bits(self, servo_id: int) -> int:
        return sum(FAULT_BITS.get(fault, 0) for fault in self.faults[servo_id])

    def _addressed(self, servo_id: int) -> list[int]:
        """The live servos a packet to ``servo_id`` reaches (broadcast: all)."""
        if servo_id == BROADCAST_ID:
            return [i for i in sorted(self.servos) if self._answers(i)]
        return self._live(servo_id)

    def _live(self, servo_id: int) -> list[int]:
        return [servo_id] if self._answers(servo_id) else []

    def _answers(self, servo_id: int) -> bool:
        return servo_id in self.servos and Fault.SILENT not in self.faults[servo_id]

    def _acks(self, servo_id: int) -> list[tuple[int, bytes]]:
        return [(i, b"") for i in self._live(servo_id)]

    def _name(self, address: int) -> str:
        return self._names.get(address, f"@{address}")

    def _values(self, address: int, payload: bytes) -> str:
        name = self._name(address)
        value = _number(payload)
        model = SERVO_MODELS[self.wiring.servo_model]
        if name in model.sign_bits and len(payload) == model.registers[name][1]:
            value = from_sign_magnitude(value, model.sign_bits[name])
        return f"{name}={value}"


def _number(payload: bytes) -> int:
    return int.from_bytes(payload, "little")
