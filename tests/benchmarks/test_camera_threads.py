"""bench-camera's per-thread CPU: thread groups from kernel names (no timing measured)."""

from __future__ import annotations

import os
import threading

from openral_bridge.os_thread import name_os_thread

from benchmarks.camera_threads import GROUPS, thread_group, thread_ticks


def test_threads_are_grouped_by_what_they_do() -> None:
    assert thread_group("openral", True, "openral") == "main"
    assert thread_group("openral-pacer", False, "openral") == "openral-pacer"
    assert thread_group("openral-render", False, "openral") == "openral-render"
    assert thread_group("llvmpipe-1", False, "openral") == "llvmpipe"
    assert thread_group("dds.shm.2116", False, "openral") == "dds"
    assert thread_group("openral", False, "openral") == "other"  # an unnamed thread
    assert thread_group("main", False, "python") == "other"  # only the real main thread


def test_this_process_has_a_main_thread_and_a_named_one() -> None:
    ready, done = threading.Event(), threading.Event()

    def run() -> None:
        name_os_thread("openral-pacer")
        ready.set()
        done.wait(15.0)

    thread = threading.Thread(target=run)
    thread.start()
    try:
        assert ready.wait(15.0)
        ticks = thread_ticks(os.getpid())
    finally:
        done.set()
        thread.join()
    assert {"main", "openral-pacer"} <= set(ticks) <= set(GROUPS)
