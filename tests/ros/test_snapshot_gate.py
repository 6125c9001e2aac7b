"""snapshot_gate.py: a paced sensor takes the scene only right after the tick that ends a
control period (as ``openral sim run`` observes it), except while no period is under way
(stopped loop, latched E-stop). A fake HAL parted in five ticks per period; the gate and the
pacer's retry are driven as the node drives them."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from openral_bridge.control_loop import ControlLoop
from openral_bridge.pacer import Pacer
from openral_bridge.snapshot_gate import period_end_gate
from rclpy.context import Context
from rclpy.node import Node

from tests.ros.ros_helpers import wait_until
from tests.ros.test_control_loop import CountingHal

pytestmark = pytest.mark.exclusive  # real-time pacing: run alone

PARTS = 5


class PartedHal(CountingHal):
    """A control period of 0.05 s stepped in five 0.01 s parts."""

    control_period_s = 0.05
    state_parts = PARTS

    def tick_part(self, action: object | None, *, glide: bool = False) -> bool:
        stepped = self.tick(action, glide=glide)
        if stepped:
            self.sim_time_s += self.control_period_s / PARTS - self.control_period_s
        return stepped


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("snapshot_gate_test", context=ros_context)
    yield node
    node.destroy_node()  # type: ignore[no-untyped-call]


def test_the_gate_opens_at_period_ends_and_says_how_long_to_wait(node: Node) -> None:
    hal = PartedHal()
    loop = ControlLoop(node, hal)  # type: ignore[arg-type]
    gate = period_end_gate(loop)
    assert gate() == 0.0  # not running: take it now
    loop.start_driven(lambda tick: None)  # ticks once: the first part of a period
    try:
        waits = [gate()]
        for _ in range(PARTS):
            loop.tick()
            waits.append(gate())
        assert waits == pytest.approx([0.045, 0.035, 0.025, 0.015, 0.0, 0.045])
        hal.estopped = True  # mid-period, frozen: the frozen scene may be taken
        assert gate() == 0.0
    finally:
        loop.stop()


def test_paced_snapshots_all_land_on_period_ends(node: Node) -> None:
    """A 10 Hz sensor job on the pacer that runs a 100 Hz parted loop, started a part into
    a period (as a reset leaves it), records the simulated time of each snapshot it takes."""
    hal = PartedHal()
    loop = ControlLoop(node, hal, lock=None)  # type: ignore[arg-type]
    gate = period_end_gate(loop)
    taken: list[float] = []

    def sensor_job() -> float | None:
        with loop.lock:
            if (delay_s := gate()) > 0.0:
                return delay_s
            taken.append(hal.sim_time_s)
        return None

    pacer = Pacer()
    pacer.start()
    try:
        loop.start(pacer)
        loop.tick()  # one part ahead of the grid, so the sensor's grid is mid-period
        pacer.every(0.1, sensor_job, "sensor")
        wait_until(lambda: len(taken) >= 8, what="eight snapshots", timeout_s=10)
    finally:
        loop.stop()
        pacer.stop()
    periods = [t / hal.control_period_s for t in taken]
    assert all(abs(p - round(p)) < 1e-6 for p in periods), periods
