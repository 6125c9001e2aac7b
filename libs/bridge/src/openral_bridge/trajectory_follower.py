"""The joint trajectory a control loop follows, one control period at a time.

A :class:`TrajectoryFollower` holds at most one running :class:`~openral_bridge.joint_path.
JointPath` and at most one waiting for its start time. Each tick of the control loop asks
it for the action of the coming period (:meth:`TrajectoryFollower.next_action`): the hold
action with the path's slots set to the path's point at the *end* of the period, which the
HAL then glides to (constant speed over the period, that speed fed forward). Slots the path
does not name keep their targets.

Replacement follows joint_trajectory_controller: a new trajectory starts at its start time
(its header stamp in simulated time, or now), from where the running one will be then; a
waiting one is dropped by a newer one. :meth:`cancel` ends both (a ``safe_action``, the
E-stop, a reset). Every method may be called from any thread.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
from openral_core.loaded import LoadedRobot
from openral_mujoco.command_limits import CommandLimits
from openral_mujoco.state import FloatArray

from openral_bridge.joint_path import (
    JointPath,
    PathLimits,
    PathStart,
    TrajectoryRequest,
    plan_path,
)

SAME_TIME_S = 1e-9
"""Times closer than this are the same instant [s]."""


def path_limits(robot: LoadedRobot) -> PathLimits:
    """The manifest's envelope per action slot of a HAL whose slots are the manifest joints:
    the command range each slot is clamped to (position limits; a gripper's command range)
    and each arm joint's ``velocity_limit`` (grippers are not slewed: no speed limit)."""
    description = robot.description
    wiring = robot.tables.hal_wiring
    grippers = wiring.grippers if wiring is not None else ()
    command = CommandLimits(description, grippers)
    speeds = wiring.velocity_limit if wiring is not None else {}
    speed = [float(speeds.get(j.name, np.inf)) for j in description.joints]
    return PathLimits(
        names=tuple(j.name for j in description.joints),
        low=command.low.copy(),
        high=command.high.copy(),
        speed=np.array(speed, dtype=np.float64),
        units=tuple("m" if j.type == "prismatic" else "rad" for j in description.joints),
    )


@dataclass(frozen=True)
class DesiredPoint:
    """Where a path wants its joints at one instant."""

    names: tuple[str, ...]
    positions: FloatArray
    velocities: FloatArray
    time_s: float
    """Simulated time of the point [s]."""


class TrajectoryFollower:
    """The running and waiting paths of one control loop (see the module doc)."""

    def __init__(self, limits: PathLimits) -> None:
        """Follow paths over the action slots ``limits`` describes."""
        self.limits = limits
        self._lock = threading.Lock()
        self._running: JointPath | None = None
        self._waiting: JointPath | None = None
        self.finished = 0
        """Paths followed to their last point."""
        self.cancelled = 0
        """Paths ended early (replaced, pre-empted, E-stop, reset)."""

    @property
    def active(self) -> bool:
        """True while a path runs or waits for its start time."""
        with self._lock:
            return self._running is not None or self._waiting is not None

    def submit(self, request: TrajectoryRequest, targets: FloatArray, now_s: float) -> JointPath:
        """Plan ``request`` from where the joints will be at its start and make it the next
        path (waiting until its start time, or running from the next tick).

        Args:
            request: The trajectory as received.
            targets: The action in force now (the hold action), one value per slot.
            now_s: Simulated time now [s] (the last tick's).

        Raises:
            PathRefused: The trajectory breaks a rule; nothing changes.
        """
        with self._lock:
            begin = now_s if request.start_s is None else max(now_s, request.start_s)
            positions, velocities = np.array(targets, dtype=np.float64), np.zeros(len(targets))
            if self._running is not None:  # where the running path will be at ``begin``
                point, speed = self._running.sample(begin)
                positions[self._running.slots] = point
                velocities[self._running.slots] = speed
            path = plan_path(request, self.limits, PathStart(now_s, positions, velocities))
            if self._waiting is not None:
                self.cancelled += 1
            self._waiting = path
            return path

    def cancel(self) -> bool:
        """End the running and the waiting path; True when there was one."""
        with self._lock:
            ended = [p for p in (self._running, self._waiting) if p is not None]
            self._running = self._waiting = None
            self.cancelled += len(ended)
            return bool(ended)

    def next_action(
        self, hold: FloatArray, now_s: float, period_s: float
    ) -> tuple[FloatArray, DesiredPoint] | None:
        """The action that ends the coming period on the path, and the desired point, or
        None when no path runs.

        Args:
            hold: The hold action (the targets in force), one value per slot.
            now_s: Simulated time at the start of the period [s].
            period_s: The control period [s].
        """
        end_s = now_s + period_s
        with self._lock:
            waiting = self._waiting
            if waiting is not None and waiting.start_s < end_s - SAME_TIME_S:
                if self._running is not None:
                    self.cancelled += 1
                self._running, self._waiting = waiting, None
            path = self._running
            if path is None:
                return None
            finishing = end_s >= path.end_s - SAME_TIME_S
            # the last period ends exactly on the last point, even a rounding error early
            positions, velocities = path.sample(path.end_s if finishing else end_s)
            if finishing:
                self._running = None
                self.finished += 1
        action = np.array(hold, dtype=np.float64)
        action[path.slots] = positions
        return action, DesiredPoint(path.names, positions, velocities, end_s)
