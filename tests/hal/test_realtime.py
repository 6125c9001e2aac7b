"""A program that keeps a robot's time runs all its threads above ordinary programs, and
only while it does (in a process of its own: the block changes the whole process)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

SCRIPT = """
import json, os, threading
from openral_hal.realtime import BACKGROUND_PRIORITY, ahead_of_other_programs

def policy(tid):
    return [os.sched_getscheduler(tid), os.sched_getparam(tid).sched_priority]

seen = {}
ready, done = threading.Event(), threading.Event()
def before_block():
    seen["old_thread_id"] = threading.get_native_id(); ready.set(); done.wait()
old = threading.Thread(target=before_block); old.start(); ready.wait()
with ahead_of_other_programs() as raised:
    seen["raised"] = raised
    seen["main"] = policy(0)
    seen["old"] = policy(seen["old_thread_id"])
    started = []
    inner = threading.Thread(target=lambda: started.append(policy(0))); inner.start(); inner.join()
    seen["started_inside"] = started[0]
seen["main_after"] = policy(0)
seen["old_after"] = policy(seen["old_thread_id"])
done.set(); old.join()
print(json.dumps(seen))
"""


def _granted() -> bool:
    try:
        os.sched_setscheduler(0, os.SCHED_RR, os.sched_param(1))
    except OSError:
        return False
    os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    return True


def test_every_thread_runs_at_the_background_priority_inside_the_block_only() -> None:
    if not _granted():
        pytest.fail("this test needs real-time scheduling (root or CAP_SYS_NICE), as CI has")
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=60, check=True
    )
    seen = json.loads(run.stdout)
    rr, other = os.SCHED_RR, os.SCHED_OTHER
    assert seen["raised"] >= 2
    assert seen["main"] == [rr, 1]
    assert seen["old"] == [rr, 1]  # a thread that was running before the block
    assert seen["started_inside"] == [rr, 1]  # inherited
    assert seen["main_after"] == [other, 0]
    assert seen["old_after"] == [other, 0]
