"""spin_until: a callback's error is said once and the executor goes on; an entity another
thread destroyed while the executor waited on it is no error (``ros topics --rate`` printed
"a ROS callback failed (InvalidHandle ...)" when its probe's subscriptions ended)."""

from __future__ import annotations

import threading

import pytest
from openral_nodes.runtime import spin_until
from rclpy.impl.implementation_singleton import rclpy_implementation


class _Context:
    def ok(self) -> bool:
        return True


class _Executor:
    """spin_once raises each of ``errors`` in turn, then sets ``stop``."""

    def __init__(self, errors: list[Exception], stop: threading.Event) -> None:
        self.context, self.errors, self.stop, self.calls = _Context(), errors, stop, 0

    def spin_once(self, timeout_sec: float) -> None:
        self.calls += 1
        if self.errors:
            raise self.errors.pop(0)
        self.stop.set()


def _spin(errors: list[Exception]) -> int:
    stop = threading.Event()
    executor = _Executor(errors, stop)
    assert spin_until(executor, stop, timeout_s=5.0) is True  # type: ignore[arg-type]
    return executor.calls


def test_a_destroyed_entity_is_not_reported(capsys: pytest.CaptureFixture[str]) -> None:
    destroyed = rclpy_implementation.InvalidHandle("cannot use Destroyable")
    assert _spin([destroyed, destroyed]) == 3
    assert capsys.readouterr().err == ""


def test_a_failing_callback_is_said_in_one_line_and_spinning_goes_on(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert _spin([ValueError("bad message")]) == 2
    printed = capsys.readouterr().err.splitlines()
    assert printed == [
        "openral: a ROS callback failed (ValueError: bad message); the executor goes on"
    ]
