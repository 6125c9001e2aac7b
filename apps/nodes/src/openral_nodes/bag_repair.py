"""Recover a rosbag2 MCAP bag whose recording was killed before it was closed.

A killed recorder leaves its ``.mcap`` file without the summary and footer that readers
need, and no ``metadata.yaml``. The chunks it wrote are complete records, though, each
holding the message types, topics and messages seen so far. :func:`repair` reads the file
record by record up to where it breaks off, and writes what it found as a new, valid bag in
the same folder; the original file is kept beside it as ``<name>.mcap.truncated``.

Record layout (the MCAP specification): one opcode byte, a little-endian u64 length, the
body. Chunks (0x06) hold schema (0x03), channel (0x04) and message (0x05) records.
"""

from __future__ import annotations

import shutil
import struct
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from openral_core.errors import OpenralError
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.metadata import parse_qos

from openral_nodes.bag_writer import typestore

MAGIC = b"\x89MCAP0\r\n"
_SCHEMA, _CHANNEL, _MESSAGE, _CHUNK = 0x03, 0x04, 0x05, 0x06


@dataclass(frozen=True)
class Repaired:
    """What :func:`repair` recovered: messages per topic, and the time they span [s]."""

    counts: dict[str, int]
    span_s: float


def repair(folder: Path) -> Repaired:
    """Rebuild ``folder`` (a bag folder whose ``.mcap`` has no index) as a valid bag.

    Raises:
        OpenralError: ``folder`` holds no ``.mcap`` file, or one that is not MCAP, or its
            bag is complete already (it has a ``metadata.yaml``).
    """
    files = sorted(folder.glob("*.mcap"))
    if not files:
        raise OpenralError(f"{folder}: no .mcap file to repair")
    if (folder / "metadata.yaml").is_file():
        raise OpenralError(f"{folder}: the bag was closed properly (it has metadata.yaml)")
    source = files[0]
    data = source.read_bytes()
    if not data.startswith(MAGIC):
        raise OpenralError(f"{source}: not an MCAP file (its first bytes are not the magic)")
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, str, str]] = {}
    messages: list[tuple[int, int, bytes]] = []
    for opcode, body in _records(data, len(MAGIC)):
        if opcode == _CHUNK:
            _read_chunk(body, schemas, channels, messages)
    with tempfile.TemporaryDirectory(dir=folder.parent) as scratch:
        rebuilt = Path(scratch) / folder.name
        counts = _write(rebuilt, channels, messages)
        source.rename(source.with_name(source.name + ".truncated"))
        for file in rebuilt.iterdir():
            shutil.move(str(file), folder / file.name)
    stamps = [stamp for _, stamp, _ in messages]
    return Repaired(counts, (max(stamps) - min(stamps)) / 1e9 if stamps else 0.0)


def _records(data: bytes, offset: int) -> Iterator[tuple[int, bytes]]:
    """Each complete record from ``offset`` on; stops where the data breaks off."""
    while offset + 9 <= len(data):
        opcode = data[offset]
        (length,) = struct.unpack_from("<Q", data, offset + 1)
        end = offset + 9 + length
        if end > len(data):
            return
        yield opcode, data[offset + 9 : end]
        offset = end


def _read_chunk(
    body: bytes,
    schemas: dict[int, str],
    channels: dict[int, tuple[str, str, str]],
    messages: list[tuple[int, int, bytes]],
) -> None:
    """Collect a chunk's schemas, channels and messages (uncompressed chunks only)."""
    offset = 8 + 8 + 8 + 4  # start, end, uncompressed size, crc
    compression, offset = _string(body, offset)
    if compression:
        raise OpenralError(f"chunks compressed with {compression!r} are not supported")
    (size,) = struct.unpack_from("<Q", body, offset)
    records = body[offset + 8 : offset + 8 + size]
    for opcode, record in _records(records, 0):
        if opcode == _SCHEMA:
            (key,) = struct.unpack_from("<H", record, 0)
            name, _ = _string(record, 2)
            schemas[key] = name
        elif opcode == _CHANNEL:
            key, schema = struct.unpack_from("<HH", record, 0)
            topic, at = _string(record, 4)
            _encoding, at = _string(record, at)
            channels[key] = (topic, schemas.get(schema, ""), _qos_text(record, at))
        elif opcode == _MESSAGE:
            key, _sequence, stamp = struct.unpack_from("<HIQ", record, 0)
            messages.append((key, stamp, record[2 + 4 + 8 + 8 :]))


def _string(data: bytes, offset: int) -> tuple[str, int]:
    (length,) = struct.unpack_from("<I", data, offset)
    start = offset + 4
    return data[start : start + length].decode(), start + length


def _qos_text(record: bytes, offset: int) -> str:
    """The ``offered_qos_profiles`` entry of a channel's metadata map ('' if absent)."""
    (size,) = struct.unpack_from("<I", record, offset)
    at, end = offset + 4, offset + 4 + size
    while at < end:
        key, at = _string(record, at)
        value, at = _string(record, at)
        if key == "offered_qos_profiles":
            return value
    return ""


def _write(
    path: Path, channels: dict[int, tuple[str, str, str]], messages: list[tuple[int, int, bytes]]
) -> dict[str, int]:
    """A new bag at ``path`` of ``messages`` on ``channels``; messages per topic."""
    types = typestore()
    counts: dict[str, int] = {}
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connections = {}
        for key, (topic, msgtype, qos) in sorted(channels.items()):
            if msgtype not in types.fielddefs:
                continue
            profiles = parse_qos(qos) if qos else []
            connections[key] = writer.add_connection(
                topic, msgtype, typestore=types, offered_qos_profiles=profiles
            )
            counts[topic] = 0
        for key, stamp, payload in sorted(messages, key=lambda m: m[1]):
            if key in connections:
                writer.write(connections[key], stamp, payload)
                counts[channels[key][0]] += 1
    return counts
