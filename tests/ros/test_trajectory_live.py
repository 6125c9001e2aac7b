"""Joint trajectories and the reset service of the franka tabletop, from outside the graph.

``openral deploy sim`` runs as a subprocess; a client on a domain of its own sends
``trajectory_msgs/JointTrajectory`` on ``/openral/joint_trajectory`` and calls
``/openral/reset`` as a ROS tool would, and reads ``/joint_states``, the trajectory state
and the wrist camera:

- panda_joint1 and panda_joint4 each move +0.5 rad in 2.0 s (a two-point trajectory):
  ``/joint_states`` is within 0.02 rad of the straight-line path at 0.5, 1.0, 1.5 and
  2.0 s after its start; the same with velocities (a cubic) against the cubic path;
- a trajectory over a velocity limit is refused whole (one warning naming the joint and
  the speed) and moves nothing;
- a ``safe_action`` pre-empts a trajectory, the E-stop aborts one;
- after 5 s of motion ``/openral/reset`` brings ``/joint_states`` back to the start state
  within 1e-6 rad and the wrist camera shows the episode's first frame again, pixel for
  pixel: the first frame after an earlier reset of the same seed, and the graph's very
  first frame when the client caught it (discovery on a loaded machine may miss it).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from openral_bridge.topics import (
    ESTOP,
    JOINT_STATES,
    JOINT_TRAJECTORY_STATE,
    RELEASE_ESTOP,
    RESET,
)
from openral_nodes.trajectory_request import trajectory_msg
from std_msgs.msg import Float64MultiArray

from tests.ros.trajectory_client import JOINTS, WRIST, Client, franka_graph, stamp_s

TOLERANCE_RAD = 0.02


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Client]:
    yield from franka_graph(tmp_path_factory.mktemp("trajectory_live"))


LEAD_TICKS = 30
"""How far ahead of the client's last /clock a trajectory's start stamp is [ticks of 0.05 s].

A trajectory reaching the graph after its start stamp begins when it arrives, so late; a
loaded CI machine delayed the client's /clock and the message by 0.65 s once (10 ticks then)."""


def _send_plus_half(
    client: Client, *, cubic: bool, lead_ticks: int = LEAD_TICKS
) -> tuple[float, np.ndarray]:
    """Send +0.5 rad on both joints in 2.0 s, starting ``lead_ticks`` ticks from now (a
    header stamp in simulated time); returns (start time, start positions)."""
    start_positions = client.positions(client.probe.latest(JOINT_STATES))
    msg = trajectory_msg(
        JOINTS,
        [0.0, 2.0],
        [start_positions.tolist(), (start_positions + 0.5).tolist()],
        [[0.0, 0.0], [0.0, 0.0]] if cubic else None,
    )
    start_s = client.now_s() + lead_ticks * 0.05  # on the tick grid: /clock is a tick's time
    msg.header.stamp.sec = int(start_s)
    msg.header.stamp.nanosec = round((start_s - int(start_s)) * 1e9)
    client.trajectory.publish(msg)
    return start_s, start_positions


@pytest.mark.parametrize("cubic", [False, True], ids=["linear", "cubic"])
def test_a_two_point_trajectory_is_followed_within_0_02_rad(client: Client, cubic: bool) -> None:
    _settle(client)
    now = time.monotonic()
    start_s, q0 = _send_plus_half(client, cubic=cubic)
    for offset in (0.5, 1.0, 1.5, 2.0):
        state = client.state_at(start_s + offset, now)
        s = min((stamp_s(state) - start_s) / 2.0, 1.0)
        shape = 3 * s**2 - 2 * s**3 if cubic else s
        expected = q0 + 0.5 * shape
        reached = client.positions(state)
        error = reached - expected
        kind = "cubic" if cubic else "linear"
        print(f"{kind} t={offset:.1f} s: error {error.round(4).tolist()} rad")
        assert np.abs(error).max() < TOLERANCE_RAD, _began(client, now, start_s)
    desired = client.probe.since(JOINT_TRAJECTORY_STATE, now)
    assert desired and list(desired[-1].msg.name) == list(JOINTS)
    assert np.allclose(desired[-1].msg.position, q0 + 0.5, atol=1e-9)
    _back(client, q0)


def test_a_trajectory_over_the_velocity_limit_is_refused_and_moves_nothing(client: Client) -> None:
    _settle(client)
    before = client.positions(client.probe.latest(JOINT_STATES))
    msg = trajectory_msg(JOINTS, [0.5], [(before + np.array([1.5, 0.0])).tolist()])  # 3 rad/s
    now = time.monotonic()
    client.trajectory.publish(msg)
    time.sleep(1.5)
    after = client.positions(client.probe.latest(JOINT_STATES))
    assert np.abs(after - before).max() < 1e-3
    assert not client.probe.since(JOINT_TRAJECTORY_STATE, now)
    err = client.stderr()
    refusals = [line for line in err.splitlines() if "trajectory refused" in line]
    assert refusals and "panda_joint1 would need 3 " in refusals[-1], refusals
    assert "velocity_limit is 2.175 rad/s" in refusals[-1]


def test_safe_action_preempts_and_estop_aborts_a_trajectory(client: Client) -> None:
    _settle(client)
    q0 = client.positions(client.probe.latest(JOINT_STATES))
    for interrupt in ("safe_action", "estop"):
        client.trajectory.publish(trajectory_msg(JOINTS, [4.0], [(q0 + 0.4).tolist()]))
        client.probe.wait_count(JOINT_TRAJECTORY_STATE, 3, time.monotonic())
        if interrupt == "safe_action":
            hold = client.probe.latest(JOINT_STATES)
            client.action.publish(Float64MultiArray(data=list(hold.position[:8])))
        else:
            assert client.call(ESTOP).message.endswith("the joint trajectory is aborted")
        time.sleep(0.3)
        quiet_from = time.monotonic()
        time.sleep(0.5)
        assert not client.probe.since(JOINT_TRAJECTORY_STATE, quiet_from), interrupt
    assert client.call(RELEASE_ESTOP).success
    _back(client, q0)


EPISODE_START_S = 0.5  # the stretch of a new episode whose joint states two resets compare [s]


def _start_of_episode(client: Client, after: float) -> tuple[float, Any, dict[float, np.ndarray]]:
    """(stamp, wrist frame, joint positions by stamp) of the start of the episode begun by a
    reset called at ``after``: the earliest frame published since (time starts again), and
    every /joint_states sample of the episode's first :data:`EPISODE_START_S` seconds (under
    load the publisher may skip a tick, so no single stamp is sure to be there)."""
    client.probe.wait_count(WRIST, 1, after, timeout_s=15.0)

    def states() -> dict[float, np.ndarray]:
        received = (r.msg for r in client.probe.since(JOINT_STATES, after))
        return {
            round(stamp_s(m), 6): np.array(m.position)
            for m in received
            if stamp_s(m) <= EPISODE_START_S
        }

    client.probe.wait(
        lambda: max(states(), default=0.0) > EPISODE_START_S - 0.1,
        15.0,
        f"/joint_states of the episode's first {EPISODE_START_S} s",
    )
    first = min(client.probe.since(WRIST, after), key=lambda r: stamp_s(r.msg)).msg
    return stamp_s(first), first, states()


def test_reset_restores_the_start_state_and_the_first_frame(client: Client) -> None:
    before = time.monotonic()
    answer = client.call(RESET)
    assert answer.success, answer.message
    assert "seed 0" in answer.message
    print(f"reset: {answer.message}")
    start_s, frame, states = _start_of_episode(client, before)
    joints = client.probe.since(JOINT_STATES, before)[-1].msg
    goal = (client.positions(joints) + 0.6).tolist()
    client.trajectory.publish(trajectory_msg(JOINTS, [5.0], [goal]))
    time.sleep(5.0)
    moved = client.probe.latest(JOINT_STATES)
    assert np.abs(client.positions(moved) - client.positions(joints)).max() > 0.3
    again = time.monotonic()
    assert client.call(RESET).success
    stamp, frame_again, states_again = _start_of_episode(client, again)
    assert stamp == start_s
    common = sorted(states.keys() & states_again.keys())
    assert common, f"no common stamp in {sorted(states)} and {sorted(states_again)}"
    for t in common:
        assert np.abs(states_again[t] - states[t]).max() < 1e-6, f"at {t} s"
    assert bytes(frame_again.data) == bytes(frame.data)
    first = client.probe.messages[WRIST][0].msg  # the graph's very first frame, if caught
    if stamp_s(first) == start_s:
        assert bytes(first.data) == bytes(frame.data)


def _began(client: Client, after: float, start_s: float) -> str:
    """When the desired path of the trajectory sent at ``after`` first moved, against its
    start stamp ``start_s`` (a failure's explanation)."""
    desired = client.probe.since(JOINT_TRAJECTORY_STATE, after)
    if not desired:
        return "no desired state was published"
    first = min(stamp_s(r.msg) for r in desired)
    return f"the desired path was first published {first - start_s:+.3f} s from its start stamp"


def _settle(client: Client, still_rad_s: float = 1e-3, timeout_s: float = 10.0) -> None:
    """Let an earlier test's motion die down: wait until both joints move slower than
    ``still_rad_s`` on /joint_states (at least 0.5 s)."""
    time.sleep(0.5)

    def still() -> bool:
        msg = client.probe.latest(JOINT_STATES)
        speeds = [abs(msg.velocity[list(msg.name).index(j)]) for j in JOINTS]
        return max(speeds) < still_rad_s

    client.probe.wait(still, timeout_s, "the joints at rest")


def _back(client: Client, q0: np.ndarray) -> None:
    """Return the two joints to ``q0`` over 2 s and wait for it."""
    here = client.positions(client.probe.latest(JOINT_STATES))
    client.trajectory.publish(trajectory_msg(JOINTS, [0.0, 2.0], [here.tolist(), q0.tolist()]))
    time.sleep(2.8)
