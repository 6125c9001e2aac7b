"""Threads that keep a bus's time ahead of ordinary ones, where the process may ask for it.

A real driver's loop reads and writes the bus every control period and latches the E-stop
when its reading is two periods old; a servo's firmware answers the bus whatever else
happens. On a busy machine either would be late while waiting behind other threads for a
core, or for Python's lock held by a thread the scheduler has put aside. The driver's loop
thread, the thread that runs the graph's tick after each reading (it holds that lock most
often), and the emulator's two threads (the one that answers the bus and the one that moves
the simulated shafts) ask for real-time round-robin scheduling: granted to root or a
process with CAP_SYS_NICE, refused (and left as they are) otherwise. Each sleeps most of the
time and does a bounded piece of work per reading.
"""

from __future__ import annotations

import contextlib
import os
import threading

PRIORITY = 10
"""Real-time priority asked for (1 to 99; low: above ordinary threads, below the system's)."""


def answer_first(priority: int = PRIORITY) -> bool:
    """Ask real-time scheduling for the calling thread; True when granted."""
    with contextlib.suppress(OSError, AttributeError):
        os.sched_setscheduler(threading.get_native_id(), os.SCHED_RR, os.sched_param(priority))
        return True
    return False
