"""ControlLoop with an end-effector target wired in (a fake target; the ticks are called
directly): it is followed between offered actions and trajectories, gliding, its points go
to ``on_ee_sample``, and every other command, the E-stop and a reset end it."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import numpy as np
import pytest
from openral_bridge.control_loop import ControlLoop
from openral_bridge.pacer import Pacer
from openral_bridge.trajectory_follower import DesiredPoint, TrajectoryFollower
from openral_mujoco.state import FloatArray
from rclpy.context import Context
from rclpy.node import Node

from tests.ros.test_control_loop import LIMITS, RAMP, CountingHal


class FakeTarget:
    """A target that moves slot ``a`` 0.01 rad per tick and keeps ``b``; logs cancels."""

    def __init__(self) -> None:
        self.active = True
        self.reasons: list[str] = []

    def next_action(
        self, hold: FloatArray, now_s: float, period_s: float
    ) -> tuple[FloatArray, DesiredPoint] | None:
        if not self.active:
            return None
        action = np.array(hold, dtype=np.float64)
        action[0] += 0.01
        point = DesiredPoint(("a",), action[:1], np.array([0.01 / period_s]), now_s + period_s)
        return action, point

    def cancel(self, reason: str = "cancelled") -> bool:
        ended, self.active = self.active, False
        if ended:
            self.reasons.append(reason)
        return ended


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("control_loop_ee_test", context=ros_context)
    yield node
    node.destroy_node()  # type: ignore[no-untyped-call]


def _wired(
    node: Node, follower: TrajectoryFollower | None = None
) -> tuple[ControlLoop, CountingHal, FakeTarget, list[DesiredPoint], list[DesiredPoint]]:
    hal, target = CountingHal(threading.Lock()), FakeTarget()
    trajectory, ee = list[DesiredPoint](), list[DesiredPoint]()
    loop = ControlLoop(
        node,
        hal,
        lock=hal.lock,
        follower=follower,
        on_sample=trajectory.append,  # type: ignore[arg-type]
    )
    loop.ee, loop.on_ee_sample = target, ee.append
    loop.tick()  # a first tick: the loop has a simulated time
    return loop, hal, target, trajectory, ee


def test_a_target_is_followed_gliding_and_its_points_go_to_on_ee_sample(node: Node) -> None:
    loop, hal, _, trajectory, ee = _wired(node)
    for _ in range(3):
        loop.tick()
    assert hal.glides == [False, True, True, True]
    assert [round(a[0], 9) for a in hal.given[1:] if a is not None] == [0.01, 0.02, 0.03]
    assert [p.time_s for p in ee] == pytest.approx([0.04, 0.06, 0.08])
    assert not trajectory and hal.unlocked_calls == 0
    assert (loop.followed, loop.applied) == (3, 0)


def test_an_offered_action_ends_the_target(node: Node) -> None:
    loop, hal, target, _, ee = _wired(node)
    loop.tick()
    loop.offer(np.array([0.5, -0.5]))
    loop.tick()
    loop.tick()
    assert target.reasons == ["a safe_action pre-empted it"]
    assert hal.events[-2:] == [("tick", [0.5, -0.5], False), ("tick", None, False)]
    assert len(ee) == 1


def test_a_trajectory_ends_the_target_and_is_followed_instead(node: Node) -> None:
    follower = TrajectoryFollower(LIMITS)
    loop, hal, target, trajectory, ee = _wired(node, follower)
    loop.tick()
    follower.submit(RAMP, hal.targets.copy(), hal.sim_time_s)
    loop.tick()
    assert target.reasons == ["a joint trajectory pre-empted it"]
    assert len(ee) == 1 and len(trajectory) == 1


def test_the_estop_and_a_reset_end_the_target(node: Node) -> None:
    loop, hal, target, _, _ = _wired(node)
    hal.estopped = True
    loop.tick()
    assert target.reasons == ["the E-stop is latched: the scene did not step"]
    hal.estopped = False
    pacer = Pacer()
    loop.start(pacer)  # (start stops first, ending any target: the next one is set after)
    target.active = True
    pacer.start()
    try:
        loop.reset()
    finally:
        loop.stop()
        assert pacer.stop()
    assert target.reasons[1:] == ["the scene was reset"]
