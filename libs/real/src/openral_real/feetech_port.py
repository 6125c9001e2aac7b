"""The feetech-servo-sdk's serial port, opened exclusively with a short blocking read, a
monotonic clock and writes that never wait on the port's drain (see
:mod:`openral_real.feetech_bus` for why each differs from the SDK's own)."""

from __future__ import annotations

import contextlib
import os
import select
import time
from collections.abc import Sequence

import scservo_sdk as scs
import serial

__all__ = ["SERIAL_READ_TIMEOUT_S", "WRITE_TIMEOUT_S", "ExclusivePort"]

SERIAL_READ_TIMEOUT_S = 0.001
"""How long one read of the port waits for bytes before the SDK looks at its timeout [s]."""
WRITE_TIMEOUT_S = 0.02
"""Longest a packet may take to be handed to the port [s]: a wedged adapter raises (and
latches the E-stop) instead of holding the driver's loop."""


class ExclusivePort(scs.PortHandler):  # type: ignore[misc]
    """The SDK's port, opened exclusively with a short blocking read (see the module doc)."""

    def setupPort(self, cflag_baud: int) -> bool:  # noqa: N802 (the SDK's name)
        if getattr(self, "is_open", False):
            self.closePort()
        self.ser = serial.Serial(
            port=self.port_name,
            baudrate=self.baudrate,
            bytesize=serial.EIGHTBITS,
            timeout=SERIAL_READ_TIMEOUT_S,
            write_timeout=WRITE_TIMEOUT_S,
            exclusive=True,
        )
        self.is_open = True
        self.ser.reset_input_buffer()
        self.tx_time_per_byte = (1000.0 / self.baudrate) * 10.0
        return True

    def clearPort(self) -> None:  # noqa: N802 (the SDK's name)
        """Nothing: the SDK drains the port's output before every packet (``tcdrain``),
        which waits for the operating system to pass the last packet on (a third of a
        second, seen on a busy machine); packets written to one port leave in order
        anyway."""

    def writePort(self, packet: Sequence[int]) -> int:  # noqa: N802 (the SDK's name)
        """Hand ``packet`` to the port; a timeout only when the port takes nothing for
        :data:`WRITE_TIMEOUT_S` (a wedged adapter). pyserial's own write also times out
        when the bytes went through but this thread got Python's lock back late."""
        data, fd = bytes(packet), self.ser.fd
        deadline, sent = time.monotonic() + WRITE_TIMEOUT_S, 0
        while sent < len(data):
            with contextlib.suppress(BlockingIOError):  # the port is non-blocking
                sent += os.write(fd, data[sent:])
                continue
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([], [fd], [], left)[1]:
                raise serial.SerialTimeoutException("Write timeout")
        return sent

    def getCurrentTime(self) -> float:  # noqa: N802 (the SDK's name)
        """Now [ms] on the monotonic clock (the SDK's wall clock can step under a timeout)."""
        return time.monotonic() * 1000.0
