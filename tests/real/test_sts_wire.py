"""Tests for sts_wire.py: the emulator's packet codec against the SDK's packets and noise."""

from __future__ import annotations

import scservo_sdk as scs
from hypothesis import given, settings
from hypothesis import strategies as st
from openral_real.emulator.sts_wire import (
    MAX_PACKET,
    Instruction,
    Packet,
    PacketReader,
    Rejected,
    checksum,
    status_packet,
)


class _Capture:
    """A port the SDK writes into (what the emulator would receive)."""

    is_using = False

    def __init__(self) -> None:
        self.sent = b""

    def clearPort(self) -> None:  # noqa: N802 (the SDK's name)
        pass

    def writePort(self, packet: list[int]) -> int:  # noqa: N802
        self.sent += bytes(packet)
        return len(packet)

    def setPacketTimeout(self, length: int) -> None:  # noqa: N802
        pass


def _sdk_bytes(call: str, *args: object) -> bytes:
    port, handler = _Capture(), scs.PacketHandler(0)
    getattr(handler, call)(port, *args)
    return port.sent


def test_the_reader_decodes_what_the_sdk_sends() -> None:
    reader = PacketReader()
    sync_read = _sdk_bytes("syncReadTx", 56, 11, [1, 2, 3], 3)
    write = _sdk_bytes("writeTxOnly", 4, 42, 2, [0x34, 0x12])
    got = reader.feed(sync_read + write)
    assert got == [
        Packet(0xFE, Instruction.SYNC_READ, bytes([56, 11, 1, 2, 3])),
        Packet(4, Instruction.WRITE, bytes([42, 0x34, 0x12])),
    ]


def test_a_packet_split_anywhere_is_put_back_together() -> None:
    data = _sdk_bytes("syncReadTx", 56, 11, [1, 2, 3, 4, 5, 6], 6)
    for cut in range(1, len(data)):
        reader = PacketReader()
        assert reader.feed(data[:cut]) == []
        assert reader.feed(data[cut:]) == [Packet(0xFE, 0x82, data[5:-1])]


def test_a_wrong_checksum_is_rejected_and_the_next_packet_still_read() -> None:
    good = Packet(1, Instruction.PING, b"").encode()
    bad = good[:-1] + bytes([good[-1] ^ 1])
    got = PacketReader().feed(bad + good)
    assert isinstance(got[0], Rejected) and "checksum" in got[0].reason
    assert got[-1] == Packet(1, Instruction.PING, b"")
    assert all(isinstance(item, Rejected) for item in got[:-1])


def test_a_status_packet_is_what_the_sdk_accepts() -> None:
    packet = status_packet(3, 0x20, bytes([0x00, 0x08]))
    assert packet[:2] == b"\xff\xff" and packet[2] == 3 and packet[4] == 0x20
    assert packet[-1] == checksum(packet[2:-1])


@settings(max_examples=300, deadline=None)
@given(st.lists(st.binary(max_size=64), max_size=20))
def test_noise_never_breaks_the_reader_and_memory_stays_bounded(chunks: list[bytes]) -> None:
    reader = PacketReader()
    for chunk in chunks:
        for item in reader.feed(chunk):
            assert isinstance(item, Packet | Rejected)
        assert reader.pending <= MAX_PACKET + 64
    reader.reset()  # a silence on the line
    assert reader.feed(Packet(9, Instruction.PING, b"").encode()) == [Packet(9, 1, b"")]


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=200).filter(lambda noise: b"\xff" not in noise))
def test_a_packet_after_headerless_noise_is_read(noise: bytes) -> None:
    got = PacketReader().feed(noise + Packet(2, Instruction.READ, b"\x38\x02").encode())
    assert got[-1] == Packet(2, Instruction.READ, b"\x38\x02")
