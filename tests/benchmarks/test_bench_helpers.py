"""The pure helpers of bench-deploy and bench-camera (no timing measured here)."""

from __future__ import annotations

import math
from pathlib import Path

from openral_core.loader import load_scene

from benchmarks.camera_bare import next_due
from benchmarks.camera_path import highest_sustained, parse_size, sized_scene, sustained
from benchmarks.deploy_launch import received_rate, stat_cpu_ticks
from tests.conftest import ROBOTS

TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


def test_cpu_ticks_are_user_system_and_waited_children_whatever_the_name() -> None:
    # pid (comm) state ppid pgrp session tty tpgid flags minflt cminflt majflt cmajflt
    # utime stime cutime cstime priority ...
    stat = "42 (python (x) y) S 1 42 42 0 -1 4194304 10 0 0 0 300 50 7 3 20 0 5 0"
    assert stat_cpu_ticks(stat) == 300 + 50 + 7 + 3


def test_received_rate_counts_intervals_between_first_and_last_arrival() -> None:
    assert received_rate([0.0, 0.1, 0.2, 0.3, 0.4]) == 10.0
    assert math.isnan(received_rate([1.0]))


def test_a_late_tick_is_not_made_up() -> None:
    assert next_due(1.0, 0.05, now=1.01) == 1.05  # on time: one period later
    assert math.isclose(next_due(1.0, 0.05, now=1.12), 1.15)  # 1.05 and 1.10 skipped


def test_the_highest_rate_sustained_stops_at_the_first_failure() -> None:
    assert sustained(10.0, {"a": 9.6, "b": 10.2})
    assert not sustained(10.0, {"a": 9.4, "b": 10.0})  # 6 % short
    assert not sustained(10.0, {"a": math.nan})
    trials = {5.0: {"a": 5.0}, 10.0: {"a": 9.9}, 20.0: {"a": 17.0}, 30.0: {"a": 29.9}}
    assert highest_sustained(trials) == 10.0  # 30 Hz passing after 20 Hz failed does not count
    assert highest_sustained({5.0: {"a": 4.0}}) is None


def test_a_sized_copy_of_a_scene_loads_with_the_new_size_and_its_rgb_cameras(
    tmp_path: Path,
) -> None:
    assert parse_size("640x480") == (640, 480)
    assert load_scene(TABLETOP).scene.cameras == ["agentview", "wrist", "front_depth"]
    for size in ((640, 480), (128, 128)):
        copy = load_scene(sized_scene(TABLETOP, size, tmp_path)).scene
        assert (copy.observation.width, copy.observation.height) == size
        assert copy.cameras == ["agentview", "wrist"]  # the depth camera is not the camera path
