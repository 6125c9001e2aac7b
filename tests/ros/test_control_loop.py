"""ControlLoop: one writer steps a simulated HAL once per control period, follows joint
trajectories (gliding) and carries resets out (a fake Tickable HAL counts what it was given;
the ticks run on a real Pacer thread)."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import numpy as np
import pytest
from openral_bridge.control_loop import ControlLoop, ResetFailed
from openral_bridge.joint_path import PathLimits, PathPoint, TrajectoryRequest
from openral_bridge.pacer import Pacer
from openral_bridge.trajectory_follower import DesiredPoint, TrajectoryFollower
from openral_hal.errors import SimulationDiverged
from openral_mujoco.state import FloatArray, JointStateSample
from rclpy.context import Context
from rclpy.node import Node

from tests.ros.ros_helpers import wait_until

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone


class CountingHal:
    """Just enough of a Tickable HAL: simulated time advances one period per tick; every
    tick, reset and callback of the loop is logged in order in :attr:`events`."""

    control_period_s = 0.02

    def __init__(self, lock: threading.Lock | None = None) -> None:
        self.given: list[FloatArray | None] = []
        self.glides: list[bool] = []
        self.events: list[object] = []
        self.sim_time_s = 0.0
        self.targets = np.zeros(2)
        self.estopped = False
        self.fail_next = False
        self.fail_reset = False
        self.resets: list[str] = []
        """The name of the thread of each reset."""
        self.lock = lock
        self.unlocked_calls = 0
        """Calls made without holding ``lock`` (when one is given)."""

    def _check_lock(self) -> None:
        if self.lock is not None and not self.lock.locked():
            self.unlocked_calls += 1

    def tick(self, action: object | None, *, glide: bool = False) -> bool:
        self._check_lock()
        if self.fail_next:
            self.fail_next = False
            raise SimulationDiverged("NaN state")
        if self.estopped:
            return False
        given = None if action is None else np.asarray(action, dtype=np.float64)
        self.given.append(given)
        self.glides.append(glide)
        self.events.append(("tick", None if given is None else given.tolist(), glide))
        if given is not None:
            self.targets = given
        self.sim_time_s += self.control_period_s
        return True

    def hold_action(self) -> FloatArray:
        self._check_lock()
        return self.targets.copy()

    def reset(self) -> str:
        self._check_lock()
        self.resets.append(threading.current_thread().name)
        self.events.append("reset")
        if self.fail_reset:
            raise RuntimeError("the scene would not load")
        self.sim_time_s, self.targets = 0.0, np.zeros(2)
        return "fake: start pose restored"

    def read_state(self) -> JointStateSample:
        self._check_lock()
        positions, zero = self.targets.copy(), np.zeros(len(self.targets))
        names = NAMES[: len(positions)]
        return JointStateSample(names, positions, zero, zero, time.monotonic_ns(), self.sim_time_s)


NAMES = ("a", "b")
LIMITS = PathLimits(NAMES, np.array([-1.0, -1.0]), np.array([1.0, 1.0]), np.array([1.0, 1.0]))
RAMP = TrajectoryRequest(("a",), (PathPoint(0.1, (0.1,)),))
"""Joint a from 0 to 0.1 rad in 0.1 s (five ticks) at its limit, 1 rad/s."""


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("control_loop_test", context=ros_context)
    yield node
    node.destroy_node()  # type: ignore[no-untyped-call]


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


# -- joint trajectories ----------------------------------------------------------------------


def _following(
    node: Node, hal: CountingHal, **kwargs: object
) -> tuple[ControlLoop, TrajectoryFollower]:
    """A loop that follows trajectories, ticked once (simulated time 0.02 s), with RAMP
    submitted from there."""
    follower = TrajectoryFollower(LIMITS)
    loop = ControlLoop(node, hal, lock=hal.lock, follower=follower, **kwargs)  # type: ignore[arg-type]
    loop.tick()
    assert loop.state is not None
    follower.submit(RAMP, hal.targets.copy(), hal.sim_time_s)
    return loop, follower


def test_a_trajectory_is_followed_tick_by_tick_gliding(node: Node) -> None:
    hal, samples = CountingHal(threading.Lock()), list[DesiredPoint]()
    loop, follower = _following(node, hal, on_sample=samples.append)
    for _ in range(6):
        loop.tick()
    actions = hal.given[1:]
    assert hal.glides[1:] == [True] * 5 + [False]  # then the hold, not a glide
    followed = np.array([a for a in actions[:5] if a is not None])
    np.testing.assert_allclose(followed[:, 0], [0.02, 0.04, 0.06, 0.08, 0.1], atol=1e-12)
    assert followed[-1, 0] == 0.1 and not followed[:, 1].any()  # b keeps its hold, 0
    assert actions[5] is None and hal.unlocked_calls == 0
    assert [p.time_s for p in samples] == pytest.approx([0.04, 0.06, 0.08, 0.1, 0.12])
    assert samples[0].names == ("a",) and samples[-1].positions.tolist() == [0.1]
    assert (loop.followed, loop.applied, loop.ticks, follower.finished) == (5, 0, 7, 1)


def test_an_offered_action_pre_empts_the_trajectory(node: Node) -> None:
    hal = CountingHal()
    loop, follower = _following(node, hal)
    loop.tick()
    loop.tick()
    assert loop.offer(np.array([0.5, -0.5])) is True
    loop.tick()
    loop.tick()
    assert hal.events[-2:] == [("tick", [0.5, -0.5], False), ("tick", None, False)]
    assert (follower.active, follower.cancelled, loop.followed, loop.applied) == (False, 1, 2, 1)
    assert loop.offer(np.array([0.0, 0.0])) is False  # nothing left to pre-empt


def test_a_tick_the_estop_stops_aborts_the_trajectory(node: Node) -> None:
    hal = CountingHal()
    loop, follower = _following(node, hal)
    loop.tick()
    hal.estopped = True
    loop.tick()
    assert (follower.active, follower.cancelled, loop.followed) == (False, 1, 1)
    hal.estopped = False
    loop.tick()
    assert hal.events[-1] == ("tick", None, False)  # holds where the trajectory stopped
    assert hal.targets.tolist() == pytest.approx([0.02, 0.0])


def test_a_failing_tick_aborts_the_trajectory(node: Node) -> None:
    hal = CountingHal()
    loop, follower = _following(node, hal)
    hal.fail_next = True
    loop.tick()
    loop.tick()
    assert (follower.active, follower.cancelled, loop.failed) == (False, 1, 1)
    assert hal.events[-1] == ("tick", None, False)


# -- reset -----------------------------------------------------------------------------------


def _logging(node: Node, hal: CountingHal) -> tuple[ControlLoop, TrajectoryFollower]:
    """A loop whose on_tick and on_reset log into the HAL's events."""
    events, follower = hal.events, TrajectoryFollower(LIMITS)
    return ControlLoop(
        node,
        hal,  # type: ignore[arg-type]
        on_tick=lambda sim_time: events.append(("on_tick", sim_time)),
        lock=hal.lock,
        follower=follower,
        on_reset=lambda: events.append(("on_reset", threading.current_thread().name)),
    ), follower


def test_a_reset_is_carried_out_by_the_next_tick_on_the_pacer_thread(
    node: Node, pacer: Pacer
) -> None:
    hal = CountingHal(threading.Lock())
    loop, follower = _logging(node, hal)
    loop.start(pacer)
    try:
        wait_until(lambda: loop.ticks >= 2, what="two ticks of the control loop")
        slow = TrajectoryRequest(("a",), (PathPoint(1.0, (0.9,)),))
        follower.submit(slow, np.zeros(2), hal.sim_time_s)
        wait_until(lambda: loop.followed >= 3, what="three ticks along the trajectory")
        assert loop.reset() == "fake: start pose restored"
        ticks = loop.ticks
        wait_until(lambda: loop.ticks >= ticks + 3, what="ticks after the reset")
    finally:
        loop.stop()
    after = hal.events[hal.events.index("reset") :]
    assert after[1:4] == [
        ("tick", None, False),  # exactly one hold tick
        ("on_tick", pytest.approx(0.02)),  # the reset scene's time
        ("on_reset", "openral-pacer"),
    ]
    assert hal.resets == ["openral-pacer"] and hal.unlocked_calls == 0
    assert (follower.active, follower.cancelled, follower.finished) == (False, 1, 0)
    assert all(e[2] is False for e in after if isinstance(e, tuple) and e[0] == "tick")


def test_an_action_waiting_for_a_tick_is_never_applied_after_a_reset(
    node: Node, pacer: Pacer
) -> None:
    hal = CountingHal()
    loop, _ = _logging(node, hal)
    loop.start(pacer)
    try:
        wait_until(lambda: loop.ticks >= 2, what="two ticks of the control loop")
        loop.offer(np.array([0.3, 0.3]))  # applied before the reset, or dropped
        loop.reset()
    finally:
        loop.stop()
    after = hal.events[hal.events.index("reset") :]
    assert ("tick", [0.3, 0.3], False) not in after and loop.applied + loop.superseded == 1


def test_a_reset_is_refused_when_the_loop_is_not_running(node: Node) -> None:
    hal = CountingHal()
    loop = _loop(node, hal)
    loop.tick()
    with pytest.raises(ResetFailed, match="the control loop is not running"):
        loop.reset()
    loop.tick()
    assert hal.resets == []


def test_a_reset_the_hal_fails_is_reported_and_the_loop_goes_on(node: Node, pacer: Pacer) -> None:
    hal = CountingHal()
    loop = _loop(node, hal)
    hal.fail_reset = True
    loop.start(pacer)
    try:
        wait_until(lambda: loop.ticks >= 2, what="two ticks of the control loop")
        with pytest.raises(ResetFailed) as failed:
            loop.reset()
        ticks = loop.ticks
        wait_until(lambda: loop.ticks >= ticks + 3, what="ticks after the failed reset")
        assert loop.running and loop.failed == 0
    finally:
        loop.stop()
    assert str(failed.value) == "the reset failed (RuntimeError: the scene would not load)"
    assert hal.resets == ["openral-pacer"]


def _unticked(node: Node, hal: CountingHal) -> ControlLoop:
    """A running loop on a pacer that never runs: only the test ticks it."""
    loop = _loop(node, hal)
    loop.start(Pacer())
    return loop


def test_a_reset_no_tick_carries_out_times_out(node: Node) -> None:
    hal = CountingHal()
    loop = _unticked(node, hal)
    started = time.monotonic()
    with pytest.raises(ResetFailed, match=r"no control tick carried the reset out within 0\.2 s"):
        loop.reset(timeout_s=0.2)
    assert 0.2 <= time.monotonic() - started < 5.0 and hal.resets == []
    loop.stop()


def test_a_reset_that_timed_out_is_not_carried_out_later(node: Node) -> None:
    hal = CountingHal()
    loop = _unticked(node, hal)
    with pytest.raises(ResetFailed):
        loop.reset(timeout_s=0.05)
    loop.tick()
    loop.stop()
    assert hal.resets == []
