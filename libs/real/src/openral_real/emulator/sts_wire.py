"""The Feetech STS wire format, as a servo on the bus sees it (the emulator's own codec).

An instruction packet is ``FF FF id length instruction params… checksum`` and a status
packet ``FF FF id length error params… checksum``, where ``length`` counts what follows it
(instruction or error, params, checksum) and ``checksum`` is the inverted low byte of the
sum of every byte after the header but itself. Words are little-endian (protocol 0).

This module is written from the protocol's description, independently of the SDK the
driver uses, so the tests that put the two on one bus check one against the other.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

HEADER = b"\xff\xff"
BROADCAST_ID = 0xFE
MAX_PACKET = 250
"""Longest packet a servo accepts (header to checksum) [bytes]."""


class Instruction(IntEnum):
    """The instructions an STS servo obeys."""

    PING = 0x01
    READ = 0x02
    WRITE = 0x03
    REG_WRITE = 0x04
    ACTION = 0x05
    SYNC_READ = 0x82
    SYNC_WRITE = 0x83


def checksum(body: bytes) -> int:
    """The checksum of ``body`` (id to last parameter)."""
    return ~sum(body) & 0xFF


@dataclass(frozen=True)
class Packet:
    """One instruction packet whose checksum was right."""

    servo_id: int
    instruction: int
    params: bytes

    def encode(self) -> bytes:
        """The packet's bytes on the wire (what a host sends)."""
        body = bytes([self.servo_id, len(self.params) + 2, self.instruction]) + self.params
        return HEADER + body + bytes([checksum(body)])


def status_packet(servo_id: int, error: int, params: bytes = b"") -> bytes:
    """A servo's reply: its id, its error byte (fault bits) and the data read."""
    body = bytes([servo_id, len(params) + 2, error & 0x7F]) + params
    return HEADER + body + bytes([checksum(body)])


@dataclass(frozen=True)
class Rejected:
    """Bytes the reader dropped, and why (a servo answers none of them)."""

    data: bytes
    reason: str


class PacketReader:
    """Splits a byte stream into instruction packets (a servo's receiver).

    Bytes before a header are dropped; a packet with a wrong checksum or an impossible
    length is ignored, as a servo ignores it (the host then times out), and the search for
    a header goes on from the byte after the bad one's start. Memory is bounded: at most one
    packet (:data:`MAX_PACKET` bytes) is buffered; :meth:`reset` drops a partial one (after
    a silence on the line, as a servo's receiver does).
    """

    def __init__(self) -> None:
        self._buffer = bytearray()

    @property
    def pending(self) -> int:
        """Bytes of a packet not yet complete."""
        return len(self._buffer)

    def reset(self) -> None:
        """Forget a partial packet."""
        self._buffer.clear()

    def feed(self, data: bytes) -> list[Packet | Rejected]:
        """Every packet (and every rejection) that ``data`` completes, in order."""
        self._buffer += data
        out: list[Packet | Rejected] = []
        while True:
            item = self._next()
            if item is None:
                return out
            out.append(item)

    def _next(self) -> Packet | Rejected | None:
        buffer = self._buffer
        start = buffer.find(HEADER)
        if start < 0:
            junk = bytes(buffer[:-1] if buffer.endswith(b"\xff") else buffer)
            del buffer[: len(junk)]
            return Rejected(junk, "no packet header") if junk else None
        if start > 0:
            junk = bytes(buffer[:start])
            del buffer[:start]
            return Rejected(junk, "bytes before a packet header")
        if len(buffer) < 4:
            return None
        servo_id, length = buffer[2], buffer[3]
        if servo_id == 0xFF or length < 2 or length + 4 > MAX_PACKET:
            del buffer[:1]  # not a packet start after all: look for the next header
            return Rejected(b"\xff", f"impossible id {servo_id} or length {length}")
        total = length + 4
        if len(buffer) < total:
            return None
        raw = bytes(buffer[:total])
        body = raw[2:-1]
        if raw[-1] != checksum(body):
            del buffer[:1]
            return Rejected(raw, f"checksum 0x{raw[-1]:02x}, expected 0x{checksum(body):02x}")
        del buffer[:total]
        return Packet(servo_id, raw[4], raw[5:-1])
