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

That alone is not enough: those threads wait for Python's lock, and the thread holding it
may be an ordinary one (ROS's executor, a publisher) that the scheduler has set aside for
another program. Measured here, on 2 cores: every start of an ``openral`` command next to
``deploy real`` latched its E-stop (the bus's reading 24 ms old). A program that keeps a
robot's time (``deploy real``, the bus emulator) therefore runs inside
:func:`ahead_of_other_programs`: all its threads, and those they start, at nice
:data:`BACKGROUND_NICE`, ahead of every ordinary program and behind its own real-time
threads. Ten ``openral`` starts next to it then latched nothing. It is the program's
choice, not a library's: a HAL never changes its process's scheduling. A thread of such a
program that keeps no time and may keep both cores busy (a camera's renderer) steps back
behind ordinary programs (:func:`behind_ordinary_programs`).
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterator
from pathlib import Path

PRIORITY = 10
"""Real-time priority asked for (1 to 99; low: above ordinary threads, below the system's)."""
BACKGROUND_NICE = -20
"""Nice value of every thread of a program that keeps a robot's time (the highest share of
the cores an ordinary thread can have; real-time round-robin at one priority would let
its threads keep a core from each other for a whole 100 ms time slice)."""
SWITCH_INTERVAL_S = 0.001
"""Python's thread switch interval while a thread keeps a robot's time [s]: that thread
waits at most this long for Python's lock (the default, 5 ms, is half a 100 Hz period)."""
IDLE_WORK_NICE = 10
"""Nice value of a thread of such a program that keeps no time (see
:func:`behind_ordinary_programs`)."""


@contextlib.contextmanager
def behind_ordinary_programs() -> Iterator[bool]:
    """Inside the block, the calling thread runs behind ordinary programs (nice
    :data:`IDLE_WORK_NICE`) when it inherited a place ahead of them
    (:func:`ahead_of_other_programs`), so threads it starts meanwhile inherit that; after
    the block it is back where it was. Yields True when it moved.

    For making a camera's renderer in a program that keeps a robot's time: llvmpipe's
    rasterising threads, made with the renderer, then stay behind ordinary programs, while
    the render thread itself (it holds Python's lock between draws) keeps its place. At
    nice -20 those threads kept a robot driver on the same cores from its deadline
    (measured: 4 of 14 ``deploy real --twin`` starts latched); with the render thread
    itself behind, a stand-in driver's own loop waited for Python's lock that thread held
    while set aside (3 goals in a row latched)."""
    tid = threading.get_native_id()
    try:
        before = os.getpriority(os.PRIO_PROCESS, tid)
    except OSError:
        yield False
        return
    moved = False
    if before < 0:
        with contextlib.suppress(OSError):
            os.setpriority(os.PRIO_PROCESS, tid, IDLE_WORK_NICE)
            moved = True
    try:
        yield moved
    finally:
        if moved:
            with contextlib.suppress(OSError):
                os.setpriority(os.PRIO_PROCESS, tid, before)


def answer_first(priority: int = PRIORITY) -> bool:
    """Ask real-time scheduling for the calling thread; True when granted."""
    with contextlib.suppress(OSError, AttributeError):
        os.sched_setscheduler(threading.get_native_id(), os.SCHED_RR, os.sched_param(priority))
        return True
    return False


@contextlib.contextmanager
def ahead_of_other_programs() -> Iterator[int]:
    """Every thread of this process at nice :data:`BACKGROUND_NICE` inside the block, and
    each it starts meanwhile (Linux threads inherit their nice value); as before after it.
    Yields how many threads were raised (0: refused, as to an unprivileged user)."""
    before = {}
    for tid in _threads():
        with contextlib.suppress(OSError):
            nice = os.getpriority(os.PRIO_PROCESS, tid)
            if nice > BACKGROUND_NICE:
                os.setpriority(os.PRIO_PROCESS, tid, BACKGROUND_NICE)
                before[tid] = nice
    try:
        yield len(before)
    finally:
        for tid in _threads():  # those raised, and those started meanwhile
            with contextlib.suppress(OSError):
                if os.getpriority(os.PRIO_PROCESS, tid) == BACKGROUND_NICE:
                    os.setpriority(os.PRIO_PROCESS, tid, before.get(tid, 0))


def _threads() -> list[int]:
    """The ids of this process's threads."""
    with contextlib.suppress(OSError):
        return [int(entry.name) for entry in Path("/proc/self/task").iterdir()]
    return [threading.get_native_id()]
