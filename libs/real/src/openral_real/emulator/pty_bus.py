"""An emulated servo bus on a pseudo-terminal: a serial port any program can open.

The emulator holds the master end of a pseudo-terminal; its slave end (``/dev/pts/N``) is
opened by a driver exactly as it opens a USB serial adapter (pyserial, the Feetech SDK).
Bytes written to it are split into packets (:class:`~openral_real.emulator.sts_wire.PacketReader`),
each obeyed by the :class:`~openral_real.emulator.bus_emulator.BusEmulator`, whose replies
are written back when their last byte would leave a real bus. The emulator keeps the slave
end open too, so a driver that closes and reopens the port finds the bus as it left it.

Unplugging (:meth:`PtyBus.unplug`) closes the pseudo-terminal: the driver's next read or
write fails as it does when a USB adapter is pulled out. :meth:`PtyBus.replug` makes a new
one (a new ``/dev/pts/N``); a ``link`` path, a symlink kept pointing at the current one,
plays the part of udev's ``/dev/serial/by-id/...`` name.
"""

from __future__ import annotations

import os
import select
import threading
import time
import tty
from pathlib import Path

from openral_hal.realtime import answer_first

from openral_real.emulator.bus_emulator import BusEmulator, Reply
from openral_real.emulator.sts_wire import Packet, PacketReader

READ_CHUNK = 4096
"""Bytes taken from the pseudo-terminal per read."""
POLL_S = 0.05
"""Longest wait for bytes before the server looks at its stop flag again [s]."""
LATE_S = 0.002
"""A reply leaving this much after its time is logged as late [s]."""
BATCH_S = 0.0005
"""Replies due this close to the previous one leave with it [s]."""
SILENCE_S = 0.005
"""A line quiet this long ends a partial packet: a servo's receiver starts afresh [s]."""


class PtyBus:
    """Serves one :class:`BusEmulator` on a pseudo-terminal (see the module doc)."""

    def __init__(self, emulator: BusEmulator, link: Path | None = None) -> None:
        """Nothing is opened until :meth:`open`."""
        self.emulator, self.link = emulator, link
        self.path = ""
        """The slave end's path while plugged in ("" otherwise)."""
        self.rejected = 0
        """Byte runs dropped (bad checksum, no header): a servo answers none of them."""
        self._fds: tuple[int, int] | None = None
        self._reader = PacketReader()
        self._last_byte = 0.0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def plugged(self) -> bool:
        """True while the pseudo-terminal is open."""
        return self._fds is not None

    def open(self) -> str:
        """Make the pseudo-terminal (raw mode, as a serial port) and return its path."""
        master, slave = os.openpty()
        tty.setraw(slave)
        with self._lock:
            self._fds = (master, slave)
            self._reader = PacketReader()
            self.path = os.ttyname(slave)
        if self.link is not None:
            temporary = self.link.with_name(self.link.name + ".new")
            temporary.unlink(missing_ok=True)
            temporary.symlink_to(self.path)
            temporary.replace(self.link)
        return self.path

    def unplug(self) -> None:
        """Close the pseudo-terminal: the driver's port fails as a pulled-out adapter does."""
        with self._lock:
            fds, self._fds = self._fds, None
            self.path = ""
        if fds is not None:
            for fd in fds:
                os.close(fd)
        self.emulator.log("UNPLUGGED")

    def replug(self) -> str:
        """A new pseudo-terminal for the same servos; returns its path."""
        if self.plugged:
            self.unplug()
        path = self.open()
        self.emulator.log(f"PLUGGED {path}")
        return path

    def start(self) -> None:
        """Serve on a thread of its own until :meth:`stop`."""
        self._stop.clear()
        self._thread = threading.Thread(target=self._serve, name="pty-bus", daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        answer_first()
        self._serve_until_stopped()

    def stop(self) -> None:
        """Stop serving and close the pseudo-terminal (idempotent)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5.0)
            self._thread = None
        if self.plugged:
            self.unplug()
        if self.link is not None and self.link.is_symlink():
            self.link.unlink()

    def _serve_until_stopped(self) -> None:
        while not self._stop.is_set():
            fds = self._fds
            if fds is None:
                self._stop.wait(POLL_S)
                continue
            try:
                ready, _, _ = select.select([fds[0]], [], [], POLL_S)
                data = os.read(fds[0], READ_CHUNK) if ready else b""
            except OSError:  # unplugged under us, or no slave open: look again
                self._stop.wait(POLL_S / 10)
                continue
            if data:
                now = time.monotonic()
                if self._reader.pending and now - self._last_byte > SILENCE_S:
                    self.rejected += 1
                    self.emulator.log(f"REJECTED {self._reader.pending} bytes cut short")
                    self._reader.reset()
                self._last_byte = now
                self._obey(data, now, fds[0])

    def _obey(self, data: bytes, arrived: float, master: int) -> None:
        """Answer every packet ``data`` completes, each reply when it would have left a real
        bus; replies due within :data:`BATCH_S` of each other leave together (each extra
        sleep is one more chance for a busy machine to answer late)."""
        for item in self._reader.feed(data):
            if not isinstance(item, Packet):
                self.rejected += 1
                self.emulator.log(f"REJECTED {item.reason}")
                continue
            replies = self.emulator.handle(item, len(item.encode()))
            for due_s, chunk in _batches(replies):
                wait = arrived + due_s - time.monotonic()
                if wait > 0:
                    time.sleep(wait)
                elif wait < -LATE_S:
                    self.emulator.log(f"LATE reply by {-wait * 1000:.1f} ms (a busy machine)")
                try:
                    os.write(master, chunk)
                except OSError:
                    return
            if replies:
                arrived = time.monotonic()


def _batches(replies: list[Reply]) -> list[tuple[float, bytes]]:
    """(when the batch is due [s], its bytes): runs of replies due within :data:`BATCH_S`."""
    batches: list[tuple[float, bytes]] = []
    for reply in replies:
        if batches and reply.at_s - batches[-1][0] <= BATCH_S:
            batches[-1] = (reply.at_s, batches[-1][1] + reply.data)
        else:
            batches.append((reply.at_s, reply.data))
    return batches
