"""RealTimeWatch: the real-time factor per window, said once per slow spell."""

from __future__ import annotations

import pytest
from openral_bridge.real_time import RealTimeWatch

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone


def _run(
    watch: RealTimeWatch, factor: float, seconds: float, start: tuple[float, float]
) -> list[float]:
    """Feed ``seconds`` of 10 Hz updates at ``factor``; return what the watch said."""
    wall, sim = start
    said = []
    for i in range(1, round(seconds * 10) + 1):
        spoken = watch.update(wall + i / 10, sim + factor * i / 10)
        if spoken is not None:
            said.append(spoken)
    return said


def test_real_time_is_never_reported() -> None:
    watch = RealTimeWatch()
    watch.update(0.0, 0.0)
    assert _run(watch, 1.0, 30.0, (0.0, 0.0)) == []
    assert watch.factor == pytest.approx(1.0)


def test_a_slow_spell_is_said_once_with_its_factor_and_again_after_catching_up() -> None:
    watch = RealTimeWatch()
    watch.update(0.0, 0.0)
    said = _run(watch, 0.5, 20.0, (0.0, 0.0))  # four slow windows, one warning
    assert said == [pytest.approx(0.5)]
    assert _run(watch, 1.0, 10.0, (20.0, 10.0)) == []  # caught up: re-armed
    assert _run(watch, 0.8, 10.0, (30.0, 20.0)) == [pytest.approx(0.8)]


def test_nothing_is_said_before_a_whole_window() -> None:
    watch = RealTimeWatch(window_s=5.0)
    watch.update(0.0, 0.0)
    assert _run(watch, 0.1, 4.9, (0.0, 0.0)) == []
    assert watch.factor is None


def test_a_restart_or_a_reset_scene_starts_a_new_window() -> None:
    watch = RealTimeWatch()
    watch.update(0.0, 10.0)
    assert watch.update(3.0, 0.5) is None  # the scene reset: time went back
    watch.restart()  # e.g. an E-stop froze time on purpose
    watch.update(10.0, 0.5)
    assert watch.update(15.0, 5.5) is None and watch.factor == pytest.approx(1.0)
