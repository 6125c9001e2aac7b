"""A joint trajectory checked against the manifest and interpolated in simulated time.

What a ROS client sends as ``trajectory_msgs/JointTrajectory`` arrives here as a
:class:`TrajectoryRequest` (plain numbers, no ROS types) and :func:`plan_path` turns it into a
:class:`JointPath`, or refuses it whole with :class:`PathRefused` and one line saying why.

The rules, as ros2_control's joint_trajectory_controller applies them to a position
interface, and the manifest's envelope on top:

- joints are manifest joints (action slots), each at most once, any subset in any order;
- ``time_from_start`` is finite and strictly increasing; positions (and velocities, when a
  point has them) are finite, one per joint; every position inside the joint's limits;
- the path starts where the joints are commanded now (or where a running path will be at
  the new one's start time): that start is the first knot; a point at time 0 must lie
  within :data:`START_TOLERANCE` of it, or else within the robot's ``start_tolerance``
  (``trajectory.start_tolerance`` of the manifest) of where the joints are *measured*: then
  the path is joined from the measured state (an arm that sags under gravity sits below its
  target, and a plan starts where the arm is); points whose time has already passed are
  dropped;
- between two knots that both have velocities the path is a cubic Hermite spline, else a
  straight line; the last point's velocities, when given, must be 0 (the joints stop there);
- nowhere may a joint move faster than its ``velocity_limit``: the fastest speed of every
  segment is computed exactly (the spline's derivative is a quadratic) and a path that
  would exceed a limit is refused, naming the joint and the speed it needs.

Accelerations and efforts of a point are not used (no quintic segments). Every check is
linear in the size of the request (a hostile message cannot stall the graph), and each
refusal carries its :class:`Refusal` kind, which the FollowJointTrajectory action turns into
its result code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError, did_you_mean
from openral_mujoco.state import FloatArray

from openral_bridge.path_segment import Segment

START_TOLERANCE = 0.01
"""Largest distance of a point at time 0 from where its joint is commanded now [rad or m]."""
MAX_POINTS = 10_000
FAR_FUTURE_S = 300.0
"""Latest start after now a trajectory may ask for [s]; a later one is taken for a clock
mismatch (a goal stamped in wall time, ~1.7e9 s, under simulated time) and refused."""
"""Most points one trajectory may have (a point per millisecond for 10 s; resource use and
the time a check takes stay bounded)."""
SPEED_SLACK = 1e-9
"""Relative slack of the velocity check (a path planned exactly at a limit passes)."""


class Refusal(StrEnum):
    """Why a trajectory was refused, in joint_trajectory_controller's terms."""

    INVALID_GOAL = "invalid_goal"
    INVALID_JOINTS = "invalid_joints"
    """A joint name that is no joint of the robot, repeated, or none at all."""
    OLD_HEADER_TIMESTAMP = "old_header_timestamp"
    """The trajectory ended before now."""


class PathRefused(OpenralError):
    """A trajectory was refused whole; the message says which field and why."""

    def __init__(self, message: str, kind: Refusal = Refusal.INVALID_GOAL) -> None:
        super().__init__(message)
        self.kind = kind


@dataclass(frozen=True)
class PathPoint:
    """One point of a request: when, where and (optionally) how fast."""

    time_from_start_s: float
    positions: tuple[float, ...]
    velocities: tuple[float, ...] = ()
    """Empty: none given (the segments on both sides of the point are then linear)."""


@dataclass(frozen=True)
class TrajectoryRequest:
    """A joint trajectory in manifest units, as received."""

    joint_names: tuple[str, ...]
    points: tuple[PathPoint, ...]
    start_s: float | None = None
    """Simulated time the trajectory starts at [s]; None: now."""
    source: str = "a joint trajectory"
    """Who sent it, for messages (``a FollowJointTrajectory goal``)."""


@dataclass(frozen=True)
class PathLimits:
    """Per action slot: its name, position range and fastest speed (inf: none)."""

    names: tuple[str, ...]
    low: FloatArray
    high: FloatArray
    speed: FloatArray
    units: tuple[str, ...] = ()
    """Each slot's position unit (``rad``, ``m``), for messages; empty: unknown."""


@dataclass(frozen=True)
class PathStart:
    """Where the commanded joints are when the new path begins, per action slot."""

    time_s: float
    positions: FloatArray
    velocities: FloatArray
    measured: FloatArray | None = None
    """Where the joints are measured now, per action slot (None: unknown)."""
    start_tolerance: float = 0.0
    """How far a point at time 0 may be from :attr:`measured` to be joined from there
    [rad or m] (0: never)."""


@dataclass(frozen=True, eq=False)
class JointPath:
    """A planned trajectory over some action slots, in simulated time (compared by identity:
    each path is one plan)."""

    names: tuple[str, ...]
    slots: npt.NDArray[np.intp]
    times_s: FloatArray
    """Knot times [s, simulated], strictly increasing; the first is the start."""
    positions: FloatArray
    """Knot positions, one row per knot, one column per slot of :attr:`slots`."""
    velocities: FloatArray
    """Knot velocities (NaN rows: the knot has none)."""
    source: str = "a joint trajectory"
    """Who sent it (:attr:`TrajectoryRequest.source`)."""

    @property
    def start_s(self) -> float:
        """When the path begins [s]."""
        return float(self.times_s[0])

    @property
    def end_s(self) -> float:
        """When the path reaches its last point [s]."""
        return float(self.times_s[-1])

    def sample(self, time_s: float) -> tuple[FloatArray, FloatArray]:
        """(positions, velocities) of the path at ``time_s``; before the start its first
        knot at rest, after the end its last knot at rest."""
        times = self.times_s
        if time_s <= times[0] or time_s >= times[-1]:
            row = self.positions[0 if time_s <= times[0] else -1]
            return row.copy(), np.zeros_like(row)
        k = int(np.searchsorted(times, time_s, side="right")) - 1
        return self.segment(k).at(time_s)

    def segment(self, k: int) -> Segment:
        """The segment from knot ``k`` to knot ``k + 1``."""
        return Segment(
            self.positions[k],
            self.positions[k + 1],
            self.velocities[k],
            self.velocities[k + 1],
            float(self.times_s[k]),
            float(self.times_s[k + 1]),
        )


def plan_path(request: TrajectoryRequest, limits: PathLimits, start: PathStart) -> JointPath:
    """Check ``request`` against ``limits`` and build its path from ``start``.

    Raises:
        PathRefused: The request breaks a rule of the module doc; nothing is planned.
    """
    slots = _slots(request.joint_names, limits.names)
    points = request.points
    if not points:
        raise PathRefused("the trajectory has no points")
    if len(points) > MAX_POINTS:
        raise PathRefused(f"the trajectory has {len(points)} points; at most {MAX_POINTS}")
    positions, velocities, offsets = _point_arrays(request, slots, limits)
    begin = start.time_s if request.start_s is None else request.start_s
    if begin - start.time_s > FAR_FUTURE_S:
        raise PathRefused(
            f"the trajectory starts at t={begin:.3f} s, {begin - start.time_s:.0f} s after now "
            f"(t={start.time_s:.3f} s, simulated): a clock mismatch? stamp it in simulated time "
            "(use_sim_time, /clock) or leave header.stamp 0 to start at once"
        )
    times = begin + offsets
    keep = times > start.time_s
    first, first_speed = start.positions[slots], start.velocities[slots]
    if offsets[0] == 0.0:  # the start itself: checked, then the start knot stands for it
        if _joined_from_measured(request.joint_names, positions[0], start, slots):
            first, first_speed = start.measured[slots], np.zeros(len(slots))  # type: ignore[index]
        keep[0] = False
    if not keep.any():
        raise PathRefused(
            f"the trajectory ended at t={times[-1]:.3f} s (simulated), before now "
            f"(t={start.time_s:.3f} s)",
            Refusal.OLD_HEADER_TIMESTAMP,
        )
    first_time = max(start.time_s, begin)
    path = JointPath(
        names=request.joint_names,
        slots=slots,
        times_s=np.concatenate([[first_time], times[keep]]),
        positions=np.vstack([first, positions[keep]]),
        velocities=np.vstack([first_speed, velocities[keep]]),
        source=request.source,
    )
    _check_speeds(path, limits)
    return path


def _slots(names: tuple[str, ...], slot_names: tuple[str, ...]) -> npt.NDArray[np.intp]:
    """Action slots of ``names``, or PathRefused for an empty, repeated or unknown one (one
    pass: linear in the number of names)."""
    if not names:
        raise PathRefused(
            "joint_names is empty; name the joints the trajectory moves", Refusal.INVALID_JOINTS
        )
    index = {name: i for i, name in enumerate(slot_names)}
    seen: set[str] = set()
    for name in names:
        if name not in index:
            hint = did_you_mean(name[:200], slot_names)
            shown = name if len(name) <= 80 else name[:80] + "…"
            raise PathRefused(
                f"joint_names: {shown!r} is not a joint of this robot{hint}",
                Refusal.INVALID_JOINTS,
            )
        if name in seen:
            raise PathRefused(f"joint_names: {name} named more than once", Refusal.INVALID_JOINTS)
        seen.add(name)
    return np.array([index[n] for n in names], dtype=np.intp)


def _point_arrays(
    request: TrajectoryRequest, slots: npt.NDArray[np.intp], limits: PathLimits
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(positions, velocities with NaN rows where none, times from start), checked."""
    width = len(slots)
    count = len(request.points)
    positions = np.empty((count, width))
    velocities = np.full((count, width), np.nan)
    offsets = np.empty(count)
    for k, point in enumerate(request.points):
        where = f"points[{k}]"
        if len(point.positions) != width:
            raise PathRefused(
                f"{where}.positions has {len(point.positions)} values; expected {width}, "
                "one per joint of joint_names"
            )
        if len(point.velocities) not in (0, width):
            raise PathRefused(
                f"{where}.velocities has {len(point.velocities)} values; expected 0 or {width}"
            )
        offsets[k] = point.time_from_start_s
        _check_point(request.joint_names, where, point, offsets, k)
        positions[k] = point.positions
        if point.velocities:
            velocities[k] = point.velocities
        _check_limits(request.joint_names, where, positions[k], slots, limits)
    last = velocities[-1]
    if not np.isnan(last).any() and np.any(last != 0.0):
        raise PathRefused(f"points[{count - 1}].velocities must be 0: the joints stop there")
    return positions, velocities, offsets


def _check_point(
    names: tuple[str, ...], where: str, point: PathPoint, offsets: FloatArray, k: int
) -> None:
    """Finite values and a time after the previous point's."""
    time_s = float(offsets[k])
    if not math.isfinite(time_s) or time_s < 0.0:
        raise PathRefused(f"{where}.time_from_start is {time_s}; expected a finite time >= 0 s")
    if k > 0 and time_s <= offsets[k - 1]:
        raise PathRefused(
            f"{where}.time_from_start ({time_s:g} s) is not after points[{k - 1}]'s "
            f"({offsets[k - 1]:g} s); times must strictly increase"
        )
    for label, row in (("positions", point.positions), ("velocities", point.velocities)):
        bad = [i for i, v in enumerate(row) if not math.isfinite(v)]
        if bad:
            value = row[bad[0]]
            raise PathRefused(f"{where}.{label}: {names[bad[0]]} is {value}; expected a number")


def _check_limits(
    names: tuple[str, ...],
    where: str,
    positions: FloatArray,
    slots: npt.NDArray[np.intp],
    limits: PathLimits,
) -> None:
    low, high = limits.low[slots], limits.high[slots]
    outside = np.flatnonzero((positions < low) | (positions > high))
    if outside.size:
        i = int(outside[0])
        raise PathRefused(
            f"{where}.positions: {names[i]} = {positions[i]:.6g} is outside its limits "
            f"[{low[i]:.6g}, {high[i]:.6g}]"
        )


def _joined_from_measured(
    names: tuple[str, ...], first: FloatArray, start: PathStart, slots: npt.NDArray[np.intp]
) -> bool:
    """Whether a point at time 0 is joined from the measured state (False: from the
    commanded one); PathRefused when it is near neither."""
    commanded = start.positions[slots]
    gap = np.abs(first - commanded)
    if not np.any(gap > START_TOLERANCE):
        return False
    measured = start.measured[slots] if start.measured is not None else None
    if measured is not None and start.start_tolerance > 0.0:
        from_measured = np.abs(first - measured)
        if not np.any(from_measured > start.start_tolerance):
            return True
    i = int(np.argmax(gap))
    where = f"{names[i]} is commanded to {commanded[i]:.6g}"
    if measured is not None:
        where += f" and measured at {measured[i]:.6g}"
    raise PathRefused(
        f"points[0] is at time 0 but {where} now, {gap[i]:.3g} away from it (at most "
        f"{START_TOLERANCE:g} from the command, or {start.start_tolerance:g} from the "
        "measured position: the robot's trajectory.start_tolerance); a point at time 0 must "
        "be where the joints are, or give it a later time"
    )


def _check_speeds(path: JointPath, limits: PathLimits) -> None:
    """Refuse a path on which some joint would exceed its velocity limit (or need an
    unbounded speed), or leave its position limits between two knots."""
    vmax = limits.speed[path.slots]
    for k in range(len(path.times_s) - 1):
        segment = path.segment(k)
        fastest = segment.fastest()
        over = np.flatnonzero(~np.isfinite(fastest) | (fastest > vmax * (1.0 + SPEED_SLACK)))
        where = "the start" if k == 0 else f"knot {k}"
        if over.size:
            i = int(over[0])
            unit = limits.units[path.slots[i]] if limits.units else "(rad or m)"
            raise PathRefused(
                f"{path.names[i]} would need {fastest[i]:.4g} {unit}/s between {where} "
                f"and t={path.times_s[k + 1]:.3f} s; its velocity_limit is {vmax[i]:g} {unit}/s"
            )
        _check_between(path, segment, limits, where)


def _check_between(path: JointPath, segment: Segment, limits: PathLimits, where: str) -> None:
    """A cubic segment may bulge past its knots: its turning points must stay inside the
    position limits too (a line stays between its knots, which are checked)."""
    cubic = segment.tangents
    if cubic is None:
        return
    unbounded = np.flatnonzero(~(np.isfinite(cubic[0]) & np.isfinite(cubic[1])))
    if unbounded.size:
        i = int(unbounded[0])
        raise PathRefused(
            f"{path.names[i]} would need an unbounded speed between {where} and the next "
            "point (a velocity too large to interpolate)"
        )
    low, high = limits.low[path.slots], limits.high[path.slots]
    for i in range(len(path.slots)):
        for time_s, q in segment.turning_points(i):
            if not low[i] <= q <= high[i]:
                raise PathRefused(
                    f"{path.names[i]} would reach {q:.6g} at t={time_s:.3f} s between "
                    f"{where} and the next point (the cubic bulges past them), outside its "
                    f"limits [{low[i]:.6g}, {high[i]:.6g}]"
                )
