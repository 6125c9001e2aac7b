"""A program that keeps a robot's time runs all its threads ahead of ordinary programs,
and only while it does (in a process of its own: the block changes the whole process)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from openral_hal.realtime import BACKGROUND_NICE, IDLE_WORK_NICE

SCRIPT = """
import json, os, threading
from openral_hal.realtime import ahead_of_other_programs

def policy(tid):
    return os.getpriority(os.PRIO_PROCESS, tid or threading.get_native_id())

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
    nice = os.getpriority(os.PRIO_PROCESS, 0)
    try:
        os.setpriority(os.PRIO_PROCESS, 0, nice - 1)
    except OSError:
        return False
    os.setpriority(os.PRIO_PROCESS, 0, nice)
    return True


def test_every_thread_runs_at_the_background_priority_inside_the_block_only() -> None:
    if not _granted():
        pytest.fail("this test needs CAP_SYS_NICE (root has it, as CI does)")
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=60, check=True
    )
    seen = json.loads(run.stdout)
    assert seen["raised"] >= 2
    assert seen["main"] == BACKGROUND_NICE
    assert seen["old"] == BACKGROUND_NICE  # a thread that was running before the block
    assert seen["started_inside"] == BACKGROUND_NICE  # inherited
    assert seen["main_after"] == 0
    assert seen["old_after"] == 0


BEHIND = """
import json, os, threading
from openral_hal.realtime import ahead_of_other_programs, behind_ordinary_programs

def nice():
    return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())

def renderer(out):
    with behind_ordinary_programs() as moved:
        out["moved"] = moved
        out["renderer"] = nice()
        child = threading.Thread(target=lambda: out.update(gl_thread=nice()))  # llvmpipe's
        child.start(); child.join()
    out["after"] = nice()

seen = {"inside": {}, "outside": {}}
with ahead_of_other_programs():
    t = threading.Thread(target=renderer, args=(seen["inside"],)); t.start(); t.join()
    seen["timekeeper"] = nice()
t = threading.Thread(target=renderer, args=(seen["outside"],)); t.start(); t.join()
print(json.dumps(seen))
"""


def test_a_timekeeping_programs_renderer_makes_its_gl_threads_behind_ordinary_ones() -> None:
    if not _granted():
        pytest.fail("this test needs CAP_SYS_NICE (root has it, as CI does)")
    run = subprocess.run(
        [sys.executable, "-c", BEHIND], capture_output=True, text=True, timeout=60, check=True
    )
    seen = json.loads(run.stdout)
    inside, outside = seen["inside"], seen["outside"]
    assert inside == {
        "moved": True,
        "renderer": IDLE_WORK_NICE,
        "gl_thread": IDLE_WORK_NICE,  # made inside the block: stays behind
        "after": BACKGROUND_NICE,  # the render thread itself is back in its place
    }
    assert seen["timekeeper"] == BACKGROUND_NICE  # the program's other threads keep their place
    assert outside == {"moved": False, "renderer": 0, "gl_thread": 0, "after": 0}
