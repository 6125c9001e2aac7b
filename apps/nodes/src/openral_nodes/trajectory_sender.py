"""Send one joint trajectory to a live graph and watch it run, as a ROS client would.

What ``openral rskill trajectory`` does: read where the joints are on
``/openral/manifest_joint_states`` (the manifest's units, the units a trajectory is given
in), send a two-point ``trajectory_msgs/JointTrajectory`` on ``/openral/joint_trajectory``
(from there at time 0 to the goals at ``seconds``; with ``cubic`` both points carry zero
velocities, so the path starts and stops smoothly), then follow
``/openral/joint_trajectory/state`` until the last desired point and compare each desired
point with the joint states of the same simulated time: the tracking error. A refusal is
read on ``/openral/joint_trajectory/refused``, where the graph publishes every one (its log
warnings are throttled), and reported at once with its reason.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from openral_bridge.topics import (
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_REFUSED,
    JOINT_TRAJECTORY_STATE,
    MANIFEST_JOINT_STATES,
)
from openral_core.errors import OpenralError, did_you_mean
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory

from openral_nodes.trajectory_request import trajectory_msg

JOINT_STATES = MANIFEST_JOINT_STATES
"""Where the joints are read: in the manifest's units, as trajectories give them."""
SETTLE_S = 1.0
"""How long after the last desired point the joints are read as reached [s, wall]."""


class TrajectoryNotRun(OpenralError):
    """The trajectory could not be sent, or the graph did not follow it."""


@dataclass
class TrajectoryReport:
    """What one sent trajectory did, per joint of ``names``."""

    names: tuple[str, ...]
    start: list[float]
    goal: list[float]
    reached: list[float] = field(default_factory=list)
    max_error: list[float] = field(default_factory=list)
    """Largest |joint state - desired point| at equal simulated times [rad or m]."""
    samples: int = 0
    """Desired points compared with a joint state of the same time."""


def parse_moves(items: list[str]) -> dict[str, float]:
    """``["panda_joint1=0.5", …]`` → ``{"panda_joint1": 0.5, …}``.

    Raises:
        TrajectoryNotRun: An item is not ``joint=number``, or names a joint twice.
    """
    moves: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not sep or not name.strip() or not math.isfinite(number):
            raise TrajectoryNotRun(f"--move {item!r}: expected joint=number, e.g. panda_joint1=0.5")
        if name.strip() in moves:
            raise TrajectoryNotRun(f"--move names {name.strip()} twice")
        moves[name.strip()] = number
    if not moves:
        raise TrajectoryNotRun("no --move given: name at least one joint=position")
    return moves


class TrajectorySender:
    """A client of one graph: sends a trajectory, records what the graph did."""

    def __init__(self, node: Node) -> None:
        """Subscribe on ``node`` (spun by the caller) and create the trajectory publisher."""
        self.node = node
        self._lock = threading.Condition()
        self._states: list[Any] = []
        self._desired: list[Any] = []
        self._refusals: list[str] = []
        node.create_subscription(JointState, JOINT_STATES, self._on_state, 50)
        node.create_subscription(String, JOINT_TRAJECTORY_REFUSED, self._on_refused, 50)
        node.create_subscription(JointState, JOINT_TRAJECTORY_STATE, self._on_desired, 50)
        self.publisher = node.create_publisher(JointTrajectory, JOINT_TRAJECTORY, 10)

    def send(
        self,
        moves: Mapping[str, float],
        seconds: float,
        *,
        relative: bool = False,
        cubic: bool = False,
        timeout_s: float = 10.0,
        on_progress: Callable[[float], None] | None = None,
    ) -> TrajectoryReport:
        """Move the joints of ``moves`` to their values (``relative``: by them) in
        ``seconds``; returns once the path has ended and the joints settled.

        Raises:
            TrajectoryNotRun: No joint states or subscriber within ``timeout_s``, an unknown
                joint, the graph refused the trajectory (the reason it published), or no
                desired point arrived.
        """
        now = self._wait(lambda: bool(self._states), timeout_s, f"no {JOINT_STATES}")
        names = tuple(moves)
        start = self._positions(now[-1], names)
        goal = [s + v if relative else v for s, v in zip(start, moves.values(), strict=True)]
        deadline = time.monotonic() + timeout_s
        while self.publisher.get_subscription_count() == 0:
            if time.monotonic() > deadline:
                raise TrajectoryNotRun(f"nobody subscribes {JOINT_TRAJECTORY} (is deploy sim up?)")
            time.sleep(0.05)
        velocities = [[0.0] * len(names)] * 2 if cubic else None
        msg = trajectory_msg(names, [0.0, seconds], [start, goal], velocities)
        with self._lock:
            sent_at = len(self._desired)
            self._refusals.clear()
        self.publisher.publish(msg)
        self._watch(sent_at, seconds, timeout_s, on_progress)
        return self._report(names, start, goal, sent_at)

    # -- internals -------------------------------------------------------------------------

    def _watch(
        self,
        sent_at: int,
        seconds: float,
        timeout_s: float,
        on_progress: Callable[[float], None] | None,
    ) -> None:
        """Until the desired points stop (the path ended) and the joints settled."""
        self._wait(
            lambda: len(self._desired) > sent_at or bool(self._refusals),
            timeout_s,
            "the graph followed no point of the trajectory",
        )
        if self._refusals:
            raise TrajectoryNotRun(f"the graph refused the trajectory: {self._refusals[0]}")
        first = _stamp(self._desired[sent_at])
        last_count, quiet_since = -1, time.monotonic()
        while time.monotonic() - quiet_since < 0.3:
            with self._lock:
                count, latest = len(self._desired), _stamp(self._desired[-1])
            if on_progress is not None:
                on_progress(min(1.0, (latest - first) / seconds) if seconds > 0 else 1.0)
            if count != last_count:
                last_count, quiet_since = count, time.monotonic()
            time.sleep(0.05)
        time.sleep(SETTLE_S)

    def _report(
        self, names: tuple[str, ...], start: list[float], goal: list[float], sent_at: int
    ) -> TrajectoryReport:
        with self._lock:
            desired, states = self._desired[sent_at:], list(self._states)
        nearest = _nearest_in_time(states)
        errors = np.zeros(len(names))
        report = TrajectoryReport(names, start, goal)
        for point in desired:
            state = nearest(_stamp(point))
            if state is None:
                continue
            wanted = self._positions(point, names)
            errors = np.maximum(errors, np.abs(np.array(self._positions(state, names)) - wanted))
            report.samples += 1
        report.reached = self._positions(states[-1], names)
        report.max_error = errors.tolist()
        return report

    def _positions(self, msg: Any, names: tuple[str, ...]) -> list[float]:
        known = list(msg.name)
        for name in names:
            if name not in known:
                hint = did_you_mean(name, known)
                raise TrajectoryNotRun(f"{name!r} is not on {JOINT_STATES}{hint}")
        return [float(msg.position[known.index(n)]) for n in names]

    def _wait(self, ready: Callable[[], bool], timeout_s: float, what: str) -> list[Any]:
        with self._lock:
            if not self._lock.wait_for(ready, timeout_s):
                raise TrajectoryNotRun(f"{what} within {timeout_s:g} s")
            return list(self._states)

    def _on_state(self, msg: Any) -> None:
        with self._lock:
            self._states.append(msg)
            del self._states[:-2000]  # bounded: ~40 s of joint states at 50 Hz
            self._lock.notify_all()

    def _on_refused(self, msg: Any) -> None:
        with self._lock:
            self._refusals.append(str(msg.data))
            self._lock.notify_all()

    def _on_desired(self, msg: Any) -> None:
        with self._lock:
            self._desired.append(msg)
            self._lock.notify_all()


def _nearest_in_time(states: list[Any]) -> Callable[[float], Any | None]:
    """The joint state stamped nearest a time, within half the states' usual spacing (a
    simulated graph stamps both at the same tick: the match is exact; a real robot's
    readings fall near the desired points' times, never on them)."""
    stamps = np.array([_stamp(s) for s in states])
    order = np.argsort(stamps)
    stamps = stamps[order]
    spacing = float(np.median(np.diff(stamps))) if len(stamps) > 2 else 0.0

    def nearest(time_s: float) -> Any | None:
        at = int(np.searchsorted(stamps, time_s))
        candidates = [i for i in (at - 1, at) if 0 <= i < len(stamps)]
        if not candidates:
            return None
        best = min(candidates, key=lambda i: abs(stamps[i] - time_s))
        if abs(stamps[best] - time_s) > max(spacing / 2.0, 1e-6):
            return None
        return states[int(order[best])]

    return nearest


def _stamp(msg: Any) -> float:
    return float(msg.header.stamp.sec) + float(msg.header.stamp.nanosec) * 1e-9
