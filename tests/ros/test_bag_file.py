"""The rosbag2 writer of ``openral ros record`` without a graph: what it writes reads back
with rosbags (types, hashes, QoS, order), a full queue drops and counts, a filling disk
stops it with one reason and a readable bag (a real 12 MiB tmpfs), a killed recording is
repaired, and an existing folder is replaced only on request and only if it is a bag."""

from __future__ import annotations

import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from openral_core.errors import OpenralError
from openral_nodes.bag_repair import repair
from openral_nodes.bag_writer import FLUSH_S, BagWriter, TopicInfo, new_bag_folder, typestore
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime as BagTime
from rosbags.rosbag2 import Reader

TYPES = typestore()
LATCHED = Qos(
    QosHistory.KEEP_LAST,
    1,
    QosReliability.RELIABLE,
    QosDurability.TRANSIENT_LOCAL,
    BagTime(0, 0),
    BagTime(0, 0),
    QosLiveliness.AUTOMATIC,
    BagTime(0, 0),
    False,
)


def _string(text: str) -> bytes:
    msg = TYPES.types["std_msgs/msg/String"](data=text)
    return bytes(TYPES.serialize_cdr(msg, "std_msgs/msg/String"))


def _image(side: int, value: int) -> bytes:
    types = TYPES.types
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="cam"
    )
    pixels = np.full(side * side * 3, value, dtype=np.uint8)
    msg = types["sensor_msgs/msg/Image"](
        header=header,
        height=side,
        width=side,
        encoding="rgb8",
        is_bigendian=0,
        step=side * 3,
        data=pixels,
    )
    return bytes(TYPES.serialize_cdr(msg, "sensor_msgs/msg/Image"))


def _read(folder: Path) -> dict[str, list[tuple[int, object]]]:
    """Each topic's (stamp [ns], message) in the bag, deserialised."""
    found: dict[str, list[tuple[int, object]]] = {}
    with Reader(folder) as reader:
        for connection, stamp, raw in reader.messages():
            message = TYPES.deserialize_cdr(raw, connection.msgtype)
            found.setdefault(connection.topic, []).append((stamp, message))
    return found


def test_messages_read_back_with_their_types_hashes_and_qos(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    writer = BagWriter(bag)
    assert writer.add_topic(TopicInfo("/robot_description", "std_msgs/msg/String", (LATCHED,)))
    assert writer.add_topic(TopicInfo("/cam", "sensor_msgs/msg/Image"))
    assert not writer.add_topic(TopicInfo("/odd", "my_msgs/msg/Odd"))
    writer.offer("/robot_description", 1_000, _string("<robot/>"))
    for i in range(5):
        writer.offer("/cam", 2_000 + i, _image(8, i))
    writer.close()
    found = _read(bag)
    assert [m.data for _, m in found["/robot_description"]] == ["<robot/>"]  # type: ignore[attr-defined]
    assert [int(m.data[0]) for _, m in found["/cam"]] == [0, 1, 2, 3, 4]  # type: ignore[attr-defined]
    assert [s for s, _ in found["/cam"]] == [2_000, 2_001, 2_002, 2_003, 2_004]
    with Reader(bag) as reader:
        connection = next(c for c in reader.connections if c.topic == "/robot_description")
        assert connection.digest == TYPES.hash_rihs01("std_msgs/msg/String")
        assert connection.ext.offered_qos_profiles[0].durability == QosDurability.TRANSIENT_LOCAL  # type: ignore[union-attr]
    assert writer.tallies["/cam"].written == 5 and writer.tallies["/cam"].dropped == 0
    assert "my_msgs/msg/Odd" in writer.skipped["/odd"] and writer.stopped is None


def test_a_full_queue_drops_and_counts_instead_of_blocking(tmp_path: Path) -> None:
    writer = BagWriter(tmp_path / "bag", queue_depth=4)
    writer.add_topic(TopicInfo("/cam", "sensor_msgs/msg/Image"))
    frame = _image(256, 7)
    start = time.monotonic()
    for _ in range(2_000):
        writer.offer("/cam", time.time_ns(), frame)
    offering_s = time.monotonic() - start
    writer.close()
    tally = writer.tallies["/cam"]
    assert tally.written + tally.dropped == 2_000 and tally.dropped > 0
    assert len(_read(tmp_path / "bag")["/cam"]) == tally.written
    assert offering_s < 5.0  # never waited for the disk (2,000 frames of 196 KB)


def test_a_nearly_full_disk_stops_the_recording_with_one_reason(tmp_path: Path) -> None:
    free = [64 * 2**20]
    writer = BagWriter(tmp_path / "bag", free_bytes=lambda _: free[0])
    writer.add_topic(TopicInfo("/cam", "sensor_msgs/msg/Image"))
    frame = _image(256, 1)
    for i in range(20):
        writer.offer("/cam", i, frame)
    _wait(lambda: writer.tallies["/cam"].written == 20)
    free[0] = 4 * 2**20  # someone else filled the disk
    for i in range(20, 60):
        writer.offer("/cam", i, frame)
    writer.close()
    assert writer.stopped is not None and "4.0 MiB free; recording stopped" in writer.stopped
    assert "\n" not in writer.stopped
    tally = writer.tallies["/cam"]
    kept = _read(tmp_path / "bag")["/cam"]
    assert 20 <= len(kept) == tally.written < 60 and tally.dropped == 60 - tally.written


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A 12 MiB tmpfs (the test runs as root, as CI does)."""
    mount = tmp_path / "disk"
    mount.mkdir()
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=12m", "tmpfs", str(mount)], check=False
    )
    if done.returncode != 0:
        pytest.skip("mounting a tmpfs needs root")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=True)


def test_a_real_full_disk_ends_with_one_line_and_a_readable_bag(small_disk: Path) -> None:
    writer = BagWriter(small_disk / "bag")
    writer.add_topic(TopicInfo("/cam", "sensor_msgs/msg/Image"))
    frame = _image(256, 3)  # 196 KB: 12 MiB hold about 60
    for i in range(200):
        writer.offer("/cam", i, frame)
        if writer.stopped is not None:
            break
        time.sleep(0.002)
    writer.close()
    assert writer.stopped is not None and "recording stopped" in writer.stopped
    kept = _read(small_disk / "bag")["/cam"]
    assert 10 < len(kept) == writer.tallies["/cam"].written < 200
    assert int(kept[-1][1].data[0]) == 3  # type: ignore[attr-defined]


def test_a_killed_recording_is_repaired_from_its_chunks(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    writer = BagWriter(bag)
    writer.add_topic(TopicInfo("/robot_description", "std_msgs/msg/String", (LATCHED,)))
    writer.add_topic(TopicInfo("/cam", "sensor_msgs/msg/Image"))
    writer.offer("/robot_description", 0, _string("<robot/>"))
    for i in range(30):
        writer.offer("/cam", 1 + i, _image(64, i))
    time.sleep(2.5 * FLUSH_S)  # the writer flushes them to the file
    killed = tmp_path / "killed"
    shutil.copytree(bag, killed)  # the file as a SIGKILL would leave it: no index, no yaml
    writer.close()
    mcap = killed / "bag.mcap"
    mcap.write_bytes(mcap.read_bytes() + b"\x05\x40\x00\x00")  # a record cut off mid-way
    with pytest.raises(Exception, match="metadata"):
        Reader(killed).open()
    repaired = repair(killed)
    assert repaired.counts == {"/robot_description": 1, "/cam": 30}
    found = _read(killed)
    assert [int(m.data[0]) for _, m in found["/cam"]] == list(range(30))  # type: ignore[attr-defined]
    assert (killed / "bag.mcap.truncated").is_file()
    with pytest.raises(OpenralError, match="closed properly"):
        repair(killed)


def test_an_existing_folder_is_replaced_only_when_asked_and_only_if_a_bag(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    BagWriter(bag).close()
    with pytest.raises(OpenralError, match=r"exists; pass --overwrite to replace it"):
        new_bag_folder(bag, overwrite=False)
    new_bag_folder(bag, overwrite=True)
    assert not bag.exists()
    notes = tmp_path / "notes"
    notes.mkdir()
    (notes / "todo.txt").write_text("keep me")
    with pytest.raises(OpenralError, match="not a bag folder"):
        new_bag_folder(notes, overwrite=True)
    assert (notes / "todo.txt").read_text() == "keep me"


def _wait(predicate: object, timeout_s: float = 10.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():  # type: ignore[operator]
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)
