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
E-stop, a reset, a cancelled goal). Whoever sent a path learns when it ends early, and why,
through :attr:`TrajectoryFollower.on_end` (a FollowJointTrajectory goal is aborted then).
Every method may be called from any thread.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import TrajectoryRules
from openral_mujoco.command_limits import CommandLimits
from openral_mujoco.state import FloatArray

from openral_bridge.joint_path import (
    JointPath,
    PathLimits,
    PathRefused,
    PathStart,
    TrajectoryRequest,
    plan_path,
)

SAME_TIME_S = 1e-9
"""Times closer than this are the same instant [s]."""
SCREEN_STEP_S = 0.01
"""A path is handed to :attr:`TrajectoryFollower.screen` sampled this often [s] (the screen
fills in straight steps between samples)."""


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


def follower_for(robot: LoadedRobot) -> TrajectoryFollower:
    """The follower of a HAL whose action slots are ``robot``'s manifest joints, with its
    envelope and start tolerance."""
    rules = robot.description.trajectory or TrajectoryRules()
    return TrajectoryFollower(path_limits(robot), rules.start_tolerance)


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

    def __init__(self, limits: PathLimits, start_tolerance: float = 0.0) -> None:
        """Follow paths over the action slots ``limits`` describes.

        Args:
            limits: The manifest's envelope per action slot.
            start_tolerance: How far a first point at time 0 may be from the measured
                position to be joined from there [rad or m] (the manifest's
                ``trajectory.start_tolerance``; 0: never).
        """
        self.limits = limits
        self.start_tolerance = float(start_tolerance)
        self.screen: Callable[[FloatArray], str | None] | None = None
        """Says where a planned path (rows of action values at :data:`SCREEN_STEP_S`)
        would touch the scene, refusing it (None: no screen; a twin scene's)."""
        self.on_end: Callable[[JointPath, str], None] | None = None
        """Told about each path that ends before its last point, and why (any thread, no
        lock of the follower held)."""
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

    def submit(
        self,
        request: TrajectoryRequest,
        targets: FloatArray,
        now_s: float,
        measured: FloatArray | None = None,
    ) -> JointPath:
        """Plan ``request`` from where the joints will be at its start and make it the next
        path (waiting until its start time, or running from the next tick).

        Args:
            request: The trajectory as received.
            targets: The action in force now (the hold action), one value per slot.
            now_s: Simulated time now [s] (the last tick's).
            measured: Where the joints are measured now, one value per slot (None: unknown;
                a first point far from the targets is then refused).

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
            start = PathStart(now_s, positions, velocities, measured, self.start_tolerance)
            path = plan_path(request, self.limits, start)
        self._screened(path, positions)
        with self._lock:
            dropped, self._waiting = self._waiting, path
            if dropped is not None:
                self.cancelled += 1
        if dropped is not None:
            self._ended(dropped, f"replaced by {path.source} before it started")
        return path

    def _screened(self, path: JointPath, targets: FloatArray) -> None:
        """Refuse ``path`` when :attr:`screen` finds a contact along it.

        Raises:
            PathRefused: The screen's line.
        """
        if self.screen is None:
            return
        times = np.arange(path.start_s, path.end_s, SCREEN_STEP_S)
        rows = np.tile(targets, (len(times) + 1, 1))
        for row, time_s in zip(rows, [*times, path.end_s], strict=True):
            row[path.slots] = path.sample(float(time_s))[0]
        contact = self.screen(rows)
        if contact is not None:
            raise PathRefused(contact)

    def reference(
        self, time_s: float
    ) -> tuple[npt.NDArray[np.intp], FloatArray, FloatArray] | None:
        """(slots, positions, velocities) the running path asks for at ``time_s`` [s] (None:
        no path runs)."""
        with self._lock:
            running = self._running
        if running is None:
            return None
        positions, velocities = running.sample(time_s)
        return running.slots, positions, velocities

    def cancel(self, reason: str = "cancelled", path: JointPath | None = None) -> bool:
        """End the running and the waiting path (only ``path``, when given); True when one
        ended. ``reason`` goes to :attr:`on_end`."""
        with self._lock:
            ended = [p for p in (self._running, self._waiting) if p is not None]
            if path is not None:
                ended = [p for p in ended if p is path]
            if any(p is self._running for p in ended):
                self._running = None
            if any(p is self._waiting for p in ended):
                self._waiting = None
            self.cancelled += len(ended)
        for gone in ended:
            self._ended(gone, reason)
        return bool(ended)

    def follows(self, path: JointPath) -> bool:
        """True while ``path`` runs or waits for its start time."""
        with self._lock:
            return path is self._running or path is self._waiting

    def _ended(self, path: JointPath, reason: str) -> None:
        if self.on_end is not None:
            self.on_end(path, reason)

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
        replaced = None
        with self._lock:
            waiting = self._waiting
            if waiting is not None and waiting.start_s < end_s - SAME_TIME_S:
                if self._running is not None:
                    self.cancelled += 1
                    replaced = self._running
                self._running, self._waiting = waiting, None
            path = self._running
        if replaced is not None and path is not None:
            self._ended(replaced, f"replaced by {path.source}")
        with self._lock:
            if path is None or path is not self._running:
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
