"""Name the calling thread in the operating system, so per-thread CPU can be told apart.

Python 3.11 names its threads only for itself; ``/proc/<pid>/task/<tid>/comm`` (``top -H``,
``ps -L``, ``bench-camera``'s per-thread table) shows every Python thread under the
program's name. :func:`name_os_thread` sets the kernel's name of the calling thread
(Linux ``prctl(PR_SET_NAME)``, at most :data:`MAX_NAME_BYTES` bytes) and does nothing where
that is not available.
"""

from __future__ import annotations

import ctypes
import sys

PR_SET_NAME = 15
"""``prctl`` option that names the calling thread (``<linux/prctl.h>``)."""
MAX_NAME_BYTES = 15
"""Longest thread name the kernel keeps (16 bytes with the terminating NUL)."""


def name_os_thread(name: str) -> bool:
    """Give the calling thread ``name`` (cut to :data:`MAX_NAME_BYTES` bytes) in the OS.

    Returns:
        True when the kernel took the name.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        encoded = name.encode("utf-8", "replace")[:MAX_NAME_BYTES]
        return int(libc.prctl(PR_SET_NAME, ctypes.c_char_p(encoded), 0, 0, 0)) == 0
    except (OSError, AttributeError):  # no libc or no prctl: names are a convenience
        return False
