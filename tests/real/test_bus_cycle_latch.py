"""The loop's write and the E-stop's latch as one step: a goal write already under way when
``estop()`` is called finishes before it returns, and after that the only goal written is
the E-stop's hold (the race a CI run caught: a moving goal 0.3 ms after the latch)."""

from __future__ import annotations

import threading
from typing import Any, cast

from openral_real.bus_cycle import BusCycle
from openral_real.feetech_bus import FeetechBus, ServoReading
from openral_real.motion_envelope import MotionEnvelope
from openral_real.servo_units import ServoUnits


class SlowBus:
    """Records goal writes; the first one waits until the test lets it through."""

    def __init__(self) -> None:
        self.goals: list[tuple[str, list[int]]] = []
        self.inside = threading.Event()
        self.let_through = threading.Event()

    def write_goals(self, goals: list[int]) -> None:
        if not self.goals:
            self.inside.set()
            assert self.let_through.wait(5.0)
        self.goals.append(("hold" if goals == [10, 20] else "move", goals))

    def write_all(self, register: str, values: list[int]) -> None:
        self.goals.append((register, values))


class Latch:
    estopped = False

    def latch_fault(self, reason: str) -> None:
        self.estopped = True


class Units:
    def steps(self, angles: Any) -> list[int]:
        return [99, 99]


class Envelope:
    def step(self) -> list[float]:
        return [1.0, 1.0]


def _reading(position: int) -> ServoReading:
    return cast(ServoReading, type("R", (), {"position": position, "faults": 0})())


def test_a_write_under_way_finishes_before_the_latch_returns_and_then_only_the_hold() -> None:
    bus, latch = SlowBus(), Latch()
    cycle = BusCycle(
        cast(FeetechBus, bus),
        cast(ServoUnits, Units()),
        cast(MotionEnvelope, Envelope()),
        latch,
        0.01,
        estop_torque_off=False,
    )
    readings = [_reading(10), _reading(20)]
    writer = threading.Thread(target=cycle._write, args=(readings,))
    writer.start()
    assert bus.inside.wait(5.0)  # past its check of the latch, on the bus
    latch.estopped, cycle.effect_pending = True, True
    settled = threading.Event()
    latcher = threading.Thread(target=lambda: (cycle.settle_latch(), settled.set()))
    latcher.start()
    assert not settled.wait(0.2)  # the latch waits for the write under way
    bus.let_through.set()
    assert settled.wait(5.0)
    writer.join(5.0)
    latcher.join(5.0)
    assert [kind for kind, _ in bus.goals] == ["move"]  # it finished before estop returned
    for _ in range(3):
        cycle._write(readings)
    assert [kind for kind, _ in bus.goals] == ["move", "hold"]  # then the hold, once
