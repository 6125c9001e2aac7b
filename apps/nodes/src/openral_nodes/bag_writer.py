"""A rosbag2 bag (MCAP storage) written on its own thread from already serialised messages.

The recorder hands over each message as the CDR bytes the publisher sent (nothing is
deserialised or serialised again) with its receive time; :class:`BagWriter` queues it and a
writer thread stores it with rosbags (metadata.yaml, RIHS01 type hashes, the publishers'
QoS profiles). The queue is bounded: when it is full a message is dropped and counted, so a
slow disk never holds up the caller.

What is written survives a crash: the MCAP data is cut into chunks, and a chunk is closed
and flushed to the file at least once a second (:data:`FLUSH_S`), so a SIGKILL loses at
most the last second; ``openral ros record --repair`` rebuilds the index of such a file.
Before the disk fills up, recording stops and the bag is closed properly
(:data:`FREE_FLOOR_BYTES` are kept for the last chunk, the index and metadata.yaml); the
reason is in :attr:`BagWriter.stopped`.
"""

from __future__ import annotations

import queue
import shutil
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from openral_core.errors import OpenralError
from rosbags.interfaces import Connection, Qos
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.storage_mcap import McapWriter
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

QUEUE_DEPTH = 20_000
"""Messages that may wait for the writer thread before new ones are dropped."""
FLUSH_S = 1.0
"""Longest time [s] a written message stays in memory before it reaches the file."""
FREE_FLOOR_BYTES = 8 * 2**20
"""Free space [bytes] recording stops at, to close the bag properly (a chunk is ~1 MiB)."""
FREE_CHECK_BYTES = 2**20
"""Bytes written between two checks of the free space."""
_STOP = None


def typestore() -> Typestore:
    """The ROS 2 Jazzy message types rosbags knows (definitions and RIHS01 hashes)."""
    return get_typestore(Stores.ROS2_JAZZY)


@dataclass(frozen=True)
class TopicInfo:
    """A topic to record: its name, message type (``pkg/msg/Name``) and the QoS profiles
    its publishers offer."""

    name: str
    msgtype: str
    qos: tuple[Qos, ...] = ()


@dataclass
class Tally:
    """What became of one topic's messages."""

    msgtype: str
    written: int = 0
    dropped: int = 0


@dataclass
class _Add:
    info: TopicInfo


@dataclass
class _Message:
    topic: str
    stamp_ns: int
    data: bytes


@dataclass
class BagWriter:
    """A new bag at ``path`` (a folder that must not exist yet) and its writer thread."""

    path: Path
    queue_depth: int = QUEUE_DEPTH
    free_bytes: Callable[[Path], int] = lambda path: shutil.disk_usage(path).free
    tallies: dict[str, Tally] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    """Topics not recorded, with the reason (a message type rosbags does not know)."""
    stopped: str | None = None
    """Why recording stopped before :meth:`close` (the disk filled up, a write failed)."""

    def __post_init__(self) -> None:
        self._types = typestore()
        self._writer = Writer(self.path, version=9, storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
        self._queue: queue.Queue[_Add | _Message | None] = queue.Queue(self.queue_depth)
        self._connections: dict[str, Connection] = {}
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, name="openral-bag", daemon=True)
        self._thread.start()

    def add_topic(self, info: TopicInfo) -> bool:
        """Record ``info``'s topic from now on; False (and a reason in :attr:`skipped`):
        its message type is not one rosbags knows."""
        if info.msgtype not in self._types.fielddefs:
            self.skipped[info.name] = f"{info.msgtype} is not a ROS 2 Jazzy type rosbags knows"
            return False
        with self._lock:
            self.tallies.setdefault(info.name, Tally(info.msgtype))
        self._queue.put(_Add(info))  # waits rather than drops: a topic is added once
        return True

    def offer(self, topic: str, stamp_ns: int, data: bytes) -> None:
        """Queue one serialised message of an added topic, received at ``stamp_ns`` [ns];
        never blocks (a full queue drops it, counted)."""
        try:
            self._queue.put_nowait(_Message(topic, stamp_ns, data))
        except queue.Full:
            with self._lock:
                self.tallies[topic].dropped += 1

    def close(self) -> None:
        """Write what is queued, then the index and metadata.yaml; idempotent."""
        if self._thread.is_alive():
            self._queue.put(_STOP)
            self._thread.join()

    def _run(self) -> None:
        written_since_check, flushed = 0, time.monotonic()
        while True:
            try:
                item = self._queue.get(timeout=FLUSH_S)
            except queue.Empty:
                item = _Message("", 0, b"")  # nothing came: only flush
            if item is _STOP:
                break
            if self.stopped is None:
                written_since_check += self._handle(item)
                if written_since_check >= FREE_CHECK_BYTES:
                    written_since_check = 0
                    self._check_space()
                if time.monotonic() - flushed >= FLUSH_S:
                    flushed = time.monotonic()
                    self._guarded(self._flush)
            elif isinstance(item, _Message) and item.topic:
                with self._lock:
                    self.tallies[item.topic].dropped += 1
        self._finish()

    def _handle(self, item: _Add | _Message) -> int:
        """Store one queued item; the bytes written."""
        if isinstance(item, _Add):
            info = item.info
            self._connections[info.name] = self._writer.add_connection(
                info.name, info.msgtype, typestore=self._types, offered_qos_profiles=info.qos
            )
            return 0
        if not item.topic:
            return 0
        if not self._guarded(
            lambda: self._writer.write(self._connections[item.topic], item.stamp_ns, item.data)
        ):
            return 0
        with self._lock:
            self.tallies[item.topic].written += 1
        return len(item.data)

    def _check_space(self) -> None:
        free = self.free_bytes(self.path)
        if free < FREE_FLOOR_BYTES:
            self.stopped = (
                f"{self.path}: the disk has {free / 2**20:.1f} MiB free; recording stopped "
                f"(it keeps {FREE_FLOOR_BYTES // 2**20} MiB to close the bag)"
            )

    def _flush(self) -> None:
        """Close the pending MCAP chunk and hand the file's buffer to the OS."""
        storage = self._writer.storage
        if isinstance(storage, McapWriter):
            if storage.chunk.bio.tell():
                storage.close_chunk()
            storage.bio.flush()

    def _guarded(self, work: Callable[[], None]) -> bool:
        """Run ``work``; a failing write (a full disk) stops recording, with the reason."""
        try:
            work()
        except OSError as error:
            self.stopped = f"{self.path}: writing failed ({error.strerror or error}); stopped"
            return False
        return True

    def _finish(self) -> None:
        """Close the bag; if even that fails, the chunks written stay repairable."""
        try:
            self._writer.close()
        except OSError as error:
            self.stopped = (
                f"{self.path}: the bag could not be closed ({error.strerror or error}); "
                f"`openral ros record {self.path} --repair` recovers what was written"
            )


def new_bag_folder(path: Path, overwrite: bool) -> None:
    """Make way for a new bag at ``path``.

    Raises:
        OpenralError: ``path`` exists and ``overwrite`` is false, or it is something other
            than a bag folder (one holding metadata.yaml or .mcap files) or an empty folder:
            that is never deleted.
    """
    if not path.exists():
        return
    if not overwrite:
        raise OpenralError(f"{path} exists; pass --overwrite to replace it")
    is_bag = path.is_dir() and (
        (path / "metadata.yaml").is_file() or any(path.glob("*.mcap")) or not any(path.iterdir())
    )
    if not is_bag:
        raise OpenralError(
            f"{path} is not a bag folder (no metadata.yaml or .mcap file); refusing to replace it"
        )
    shutil.rmtree(path)
