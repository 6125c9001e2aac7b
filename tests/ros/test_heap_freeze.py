"""Tests for heap_freeze.py: the heap is frozen only when enabled, and thawed again."""

from __future__ import annotations

import gc

from openral_nodes.heap_freeze import HeapFreeze


def test_freezing_is_off_unless_enabled_and_thaws_back() -> None:
    assert gc.get_freeze_count() == 0
    idle = HeapFreeze()
    idle.freeze()
    assert gc.get_freeze_count() == 0 and not idle.frozen
    heap = HeapFreeze(enabled=True)
    try:
        heap.freeze()
        frozen = gc.get_freeze_count()
        assert frozen > 1000 and heap.frozen  # this process's modules and objects
        heap.freeze()
        assert gc.get_freeze_count() == frozen  # once
    finally:
        heap.thaw()
    assert gc.get_freeze_count() == 0 and not heap.frozen
    heap.thaw()
    assert gc.get_freeze_count() == 0
