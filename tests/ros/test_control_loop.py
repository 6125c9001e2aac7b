"""ControlLoop: one writer steps a simulated HAL once per control period (a fake Tickable
HAL counts what it was given; the timer is a real rclpy timer)."""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest
from openral_bridge.control_loop import ControlLoop
from openral_hal.errors import SimulationDiverged
from openral_mujoco.state import FloatArray, JointStateSample
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.node import Node

from tests.ros.ros_helpers import wait_until


class CountingHal:
    """Just enough of a Tickable HAL: simulated time advances one period per tick."""

    control_period_s = 0.02

    def __init__(self) -> None:
        self.given: list[FloatArray | None] = []
        self.sim_time_s = 0.0
        self.estopped = False
        self.fail_next = False

    def tick(self, action: object | None) -> bool:
        if self.fail_next:
            self.fail_next = False
            raise SimulationDiverged("NaN state")
        if self.estopped:
            return False
        self.given.append(None if action is None else np.asarray(action))
        self.sim_time_s += self.control_period_s
        return True

    def read_state(self) -> JointStateSample:
        zero = np.zeros(1)
        return JointStateSample(("j",), zero, zero, zero, time.monotonic_ns(), self.sim_time_s)


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("control_loop_test", context=ros_context)
    yield node
    node.destroy_node()


def _loop(node: Node, hal: CountingHal, ticked: list[float | None] | None = None) -> ControlLoop:
    on_tick = None if ticked is None else (lambda sim_time: ticked.append(sim_time))
    return ControlLoop(node, hal, on_tick=on_tick)  # type: ignore[arg-type]


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


def test_start_ticks_at_once_then_on_the_timer_and_stop_ends_it(
    ros_context: Context, node: Node
) -> None:
    hal = CountingHal()
    loop = _loop(node, hal)
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.call(loop.start)
        assert loop.running
        wait_until(lambda: loop.ticks >= 10, what="ten ticks of the control loop")
        spinner.call(loop.stop)
        stopped = loop.ticks
        time.sleep(0.1)  # five periods: a live timer would have ticked
    assert loop.ticks == stopped and not loop.running
    assert len(list(node.timers)) == 0


def test_a_pending_action_dropped_by_stop_is_counted(node: Node) -> None:
    loop = _loop(node, CountingHal())
    loop.offer(np.array([1.0]))
    loop.stop()
    assert loop.superseded == 1
