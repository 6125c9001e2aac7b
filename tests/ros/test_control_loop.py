"""ControlLoop: one writer steps a simulated HAL once per control period (a fake Tickable
HAL counts what it was given; the ticks run on a real Pacer thread)."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import numpy as np
import pytest
from openral_bridge.control_loop import ControlLoop
from openral_bridge.pacer import Pacer
from openral_hal.errors import SimulationDiverged
from openral_mujoco.state import FloatArray, JointStateSample
from rclpy.context import Context
from rclpy.node import Node

from tests.ros.ros_helpers import wait_until


class CountingHal:
    """Just enough of a Tickable HAL: simulated time advances one period per tick."""

    control_period_s = 0.02

    def __init__(self, lock: threading.Lock | None = None) -> None:
        self.given: list[FloatArray | None] = []
        self.sim_time_s = 0.0
        self.estopped = False
        self.fail_next = False
        self.lock = lock
        self.unlocked_calls = 0
        """Calls made without holding ``lock`` (when one is given)."""

    def _check_lock(self) -> None:
        if self.lock is not None and not self.lock.locked():
            self.unlocked_calls += 1

    def tick(self, action: object | None) -> bool:
        self._check_lock()
        if self.fail_next:
            self.fail_next = False
            raise SimulationDiverged("NaN state")
        if self.estopped:
            return False
        self.given.append(None if action is None else np.asarray(action))
        self.sim_time_s += self.control_period_s
        return True

    def read_state(self) -> JointStateSample:
        self._check_lock()
        zero = np.zeros(1)
        return JointStateSample(("j",), zero, zero, zero, time.monotonic_ns(), self.sim_time_s)


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("control_loop_test", context=ros_context)
    yield node
    node.destroy_node()


def _loop(node: Node, hal: CountingHal, ticked: list[float | None] | None = None) -> ControlLoop:
    on_tick = None if ticked is None else (lambda sim_time: ticked.append(sim_time))
    return ControlLoop(node, hal, on_tick=on_tick, lock=hal.lock)  # type: ignore[arg-type]


def test_the_newest_action_wins_and_the_replaced_ones_are_counted(node: Node) -> None:
    hal, ticked = CountingHal(), list[float | None]()
    loop = _loop(node, hal, ticked)
    for value in (1.0, 2.0, 3.0):
        loop.offer(np.array([value]))
    loop.tick()
    loop.tick()  # nothing new: hold
    assert [None if a is None else a.tolist() for a in hal.given] == [[3.0], None]
    assert (loop.superseded, loop.applied, loop.ticks, len(ticked)) == (2, 1, 2, 2)
    assert ticked == pytest.approx([0.02, 0.04])  # each tick's simulated time, handed on


def test_a_failing_tick_is_counted_and_the_loop_goes_on(node: Node) -> None:
    hal = CountingHal()
    loop = _loop(node, hal)
    hal.fail_next = True
    loop.tick()
    loop.tick()
    assert (loop.failed, loop.ticks) == (1, 1)


def test_an_estopped_hal_does_not_advance_and_is_not_counted(node: Node) -> None:
    hal = CountingHal()
    loop = _loop(node, hal)
    hal.estopped = True
    loop.offer(np.array([1.0]))
    loop.tick()
    assert (loop.ticks, loop.applied, hal.sim_time_s) == (0, 0, 0.0)
    assert loop.superseded == 1  # the action that waited for the tick is dropped, counted


def test_each_tick_steps_and_reads_the_hal_holding_the_lock_and_keeps_the_state(
    node: Node,
) -> None:
    hal = CountingHal(threading.Lock())
    loop = _loop(node, hal)
    assert loop.state is None
    loop.tick()
    loop.tick()
    assert hal.unlocked_calls == 0 and len(hal.given) == 2
    assert loop.state is not None and loop.state.sim_time_s == pytest.approx(0.04)
    hal.fail_next = True
    loop.tick()
    assert loop.state is None  # after a failed tick the HAL is read again


def test_offers_from_another_thread_are_each_applied_or_counted(node: Node) -> None:
    hal = CountingHal()
    loop = _loop(node, hal)
    offered = 2000

    def offer() -> None:
        for value in range(offered):
            loop.offer(np.array([float(value)]))

    sender = threading.Thread(target=offer)
    sender.start()
    while sender.is_alive():
        loop.tick()
    sender.join()
    loop.tick()
    assert loop.applied + loop.superseded == offered
    applied = [action.tolist() for action in hal.given if action is not None]
    assert [offered - 1.0] in applied  # the newest is never superseded


def test_start_ticks_at_once_then_on_the_pacer_and_stop_ends_it(node: Node) -> None:
    hal = CountingHal(threading.Lock())
    loop = _loop(node, hal)
    pacer = Pacer()
    loop.start(pacer)
    assert loop.ticks == 1 and loop.running  # before the pacer runs
    pacer.start()
    try:
        wait_until(lambda: loop.ticks >= 10, what="ten ticks of the control loop")
        loop.stop()
        stopped = loop.ticks
        assert pacer.jobs == () and not loop.running
        time.sleep(0.1)  # five periods: a scheduled tick would have run
        assert loop.ticks == stopped
    finally:
        assert pacer.stop()
    assert hal.unlocked_calls == 0


def test_a_pending_action_dropped_by_stop_is_counted(node: Node) -> None:
    loop = _loop(node, CountingHal())
    loop.offer(np.array([1.0]))
    loop.stop()
    assert loop.superseded == 1
