"""name_os_thread: the kernel shows a thread's name (Linux), cut to 15 bytes."""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import pytest
from openral_bridge.os_thread import name_os_thread
from openral_bridge.pacer import Pacer

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux /proc")


def comm(native_id: int) -> str:
    return Path(f"/proc/self/task/{native_id}/comm").read_text().strip()


def test_a_thread_is_named_in_the_kernel_and_long_names_are_cut() -> None:
    seen: list[tuple[bool, str]] = []

    def run() -> None:
        named = name_os_thread("openral-a-rather-long-name")
        seen.append((named, comm(threading.get_native_id())))

    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    assert seen == [(True, "openral-a-rathe")]


def test_the_pacer_thread_carries_its_name() -> None:
    ids: list[int] = []
    called = threading.Event()
    pacer = Pacer(name="paced-test")
    pacer.every(0.01, lambda: (ids.append(threading.get_native_id()), called.set()), "job")
    pacer.start()
    try:
        assert called.wait(15.0)
        assert comm(ids[0]) == "paced-test"
    finally:
        assert pacer.stop()
