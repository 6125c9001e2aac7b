"""The drivers' writes and the E-stop's latch as one step: a goal already being written when
``estop()`` is called goes out before it returns, and after that the only goal written is
the E-stop's hold (the race a CI run caught: a moving goal 0.3 ms after the latch). For the
Feetech bus loop and for the ros2_control HAL, with a bus and a link that hold their first
write until the test lets it go."""

from __future__ import annotations

import threading
import time
from typing import Any, cast

import numpy as np
from openral_core import open_robot_by_id
from openral_mujoco.state import JointStateSample
from openral_real.bus_cycle import BusCycle
from openral_real.feetech_bus import FeetechBus, ServoReading
from openral_real.motion_envelope import MotionEnvelope
from openral_real.ros2_control_hal import Ros2ControlHal
from openral_real.ros2_control_link import Ros2ControlLink
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


class SlowLink:
    """A ros2_control link whose first trajectory point waits until the test lets it go."""

    def __init__(self) -> None:
        self.sent: list[str] = []
        self.inside, self.let_through = threading.Event(), threading.Event()

    def send_point(self, names: list[str], positions: Any, after_s: float) -> None:
        if not self.inside.is_set():  # the first call only
            self.inside.set()
            assert self.let_through.wait(5.0)
            time.sleep(0.05)  # a later send would overtake it here
        self.sent.append("point")

    def send_gripper(self, position: float, effort: float) -> None:
        self.sent.append("gripper")

    def cancel_gripper(self) -> None:
        self.sent.append("cancel")


def test_a_ros2_control_goal_under_way_goes_out_before_the_hold_never_after() -> None:
    hal = Ros2ControlHal(open_robot_by_id("franka_panda"), "robot")
    link = SlowLink()
    names = list(hal.joint_names)
    hal._latest = JointStateSample(
        names, np.zeros(len(names)), np.zeros(len(names)), np.zeros(len(names)), 1, None, False
    )
    hal._link, hal._running = cast(Ros2ControlLink, link), True
    hal._envelope.start(hal.measured_angles())
    writer = threading.Thread(target=hal.write_cycle)
    writer.start()
    assert link.inside.wait(5.0)  # past its check of the latch, sending
    latched = threading.Event()
    latcher = threading.Thread(target=lambda: (hal.estop(), latched.set()))
    latcher.start()
    assert not latched.wait(0.2)  # estop() waits for the goal under way
    link.let_through.set()
    assert latched.wait(5.0)
    writer.join(5.0)
    latcher.join(5.0)
    hal.write_cycle()  # latched: nothing more
    assert link.sent[0] == "point" and link.sent[-2:] == ["point", "cancel"]  # goal, then hold
    assert link.sent.count("point") == 2
