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
  within :data:`START_TOLERANCE` of it; points whose time has already passed are dropped;
- between two knots that both have velocities the path is a cubic Hermite spline, else a
  straight line; the last point's velocities, when given, must be 0 (the joints stop there);
- nowhere may a joint move faster than its ``velocity_limit``: the fastest speed of every
  segment is computed exactly (the spline's derivative is a quadratic) and a path that
  would exceed a limit is refused, naming the joint and the speed it needs.

Accelerations and efforts of a point are not used (no quintic segments).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError, did_you_mean
from openral_mujoco.state import FloatArray

START_TOLERANCE = 0.01
"""Largest distance of a point at time 0 from where its joint is commanded now [rad or m]."""
MAX_POINTS = 100_000
"""Most points one trajectory may have (resource use stays bounded)."""
SPEED_SLACK = 1e-9
"""Relative slack of the velocity check (a path planned exactly at a limit passes)."""


class PathRefused(OpenralError):
    """A trajectory was refused whole; the message says which field and why."""


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


@dataclass(frozen=True)
class JointPath:
    """A planned trajectory over some action slots, in simulated time."""

    names: tuple[str, ...]
    slots: npt.NDArray[np.intp]
    times_s: FloatArray
    """Knot times [s, simulated], strictly increasing; the first is the start."""
    positions: FloatArray
    """Knot positions, one row per knot, one column per slot of :attr:`slots`."""
    velocities: FloatArray
    """Knot velocities (NaN rows: the knot has none)."""

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
        return _segment_at(self, k, time_s)


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
    times = begin + offsets
    keep = times > start.time_s
    if offsets[0] == 0.0:  # the start itself: checked, then the start knot stands for it
        _check_at_start(request.joint_names, positions[0], start.positions[slots])
        keep[0] = False
    if not keep.any():
        raise PathRefused(
            f"the trajectory ended at t={times[-1]:.3f} s (simulated), before now "
            f"(t={start.time_s:.3f} s)"
        )
    first_time = max(start.time_s, begin)
    path = JointPath(
        names=request.joint_names,
        slots=slots,
        times_s=np.concatenate([[first_time], times[keep]]),
        positions=np.vstack([start.positions[slots], positions[keep]]),
        velocities=np.vstack([start.velocities[slots], velocities[keep]]),
    )
    _check_speeds(path, limits)
    return path


def _slots(names: tuple[str, ...], slot_names: tuple[str, ...]) -> npt.NDArray[np.intp]:
    """Action slots of ``names``, or PathRefused for an empty, repeated or unknown one."""
    if not names:
        raise PathRefused("joint_names is empty; name the joints the trajectory moves")
    index = {name: i for i, name in enumerate(slot_names)}
    for name in names:
        if name not in index:
            hint = did_you_mean(name, slot_names)
            raise PathRefused(f"joint_names: {name!r} is not a joint of this robot{hint}")
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise PathRefused(f"joint_names: {', '.join(repeated)} named more than once")
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


def _check_at_start(names: tuple[str, ...], first: FloatArray, now: FloatArray) -> None:
    """A point at time 0 must be where the joints are commanded now."""
    gap = np.abs(first - now)
    far = np.flatnonzero(gap > START_TOLERANCE)
    if far.size:
        i = int(far[0])
        raise PathRefused(
            f"points[0] is at time 0 but {names[i]} is commanded to {now[i]:.6g} now, "
            f"{gap[i]:.3g} away (at most {START_TOLERANCE:g}); a point at time 0 must be "
            "the start, or give it a later time"
        )


def _check_speeds(path: JointPath, limits: PathLimits) -> None:
    """Refuse a path on which some joint would exceed its velocity limit (or need an
    unbounded speed), or leave its position limits between two knots."""
    vmax = limits.speed[path.slots]
    for k in range(len(path.times_s) - 1):
        fastest = _fastest(path, k)
        over = np.flatnonzero(~np.isfinite(fastest) | (fastest > vmax * (1.0 + SPEED_SLACK)))
        segment = "the start" if k == 0 else f"knot {k}"
        if over.size:
            i = int(over[0])
            unit = limits.units[path.slots[i]] if limits.units else "(rad or m)"
            raise PathRefused(
                f"{path.names[i]} would need {fastest[i]:.4g} {unit}/s between {segment} "
                f"and t={path.times_s[k + 1]:.3f} s; its velocity_limit is {vmax[i]:g} {unit}/s"
            )
        _check_between(path, k, limits, segment)


def _check_between(path: JointPath, k: int, limits: PathLimits, segment: str) -> None:
    """A cubic segment may bulge past its knots: its turning points must stay inside the
    position limits too (a line stays between its knots, which are checked)."""
    cubic = _hermite(path, k)
    if cubic is None:
        return
    p0, p1, m0, m1, _ = cubic
    unbounded = np.flatnonzero(~(np.isfinite(m0) & np.isfinite(m1)))
    if unbounded.size:
        i = int(unbounded[0])
        raise PathRefused(
            f"{path.names[i]} would need an unbounded speed between {segment} and the next "
            "point (a velocity too large to interpolate)"
        )
    a = 6 * p0 + 3 * m0 - 6 * p1 + 3 * m1  # q'(s)·T = a s² + b s + c
    b = -6 * p0 - 4 * m0 + 6 * p1 - 2 * m1
    low, high = limits.low[path.slots], limits.high[path.slots]
    for i in range(len(path.slots)):
        for s in _roots(float(a[i]), float(b[i]), float(m0[i])):
            q = (2 * s**3 - 3 * s**2 + 1) * p0[i] + (s**3 - 2 * s**2 + s) * m0[i]
            q += (-2 * s**3 + 3 * s**2) * p1[i] + (s**3 - s**2) * m1[i]
            if not low[i] <= q <= high[i]:
                time_s = path.times_s[k] + s * (path.times_s[k + 1] - path.times_s[k])
                raise PathRefused(
                    f"{path.names[i]} would reach {q:.6g} at t={time_s:.3f} s between "
                    f"{segment} and the next point (the cubic bulges past them), outside its "
                    f"limits [{low[i]:.6g}, {high[i]:.6g}]"
                )


def _roots(a: float, b: float, c: float) -> list[float]:
    """Roots of a s² + b s + c inside (0, 1)."""
    if a == 0.0:
        found = [-c / b] if b != 0.0 else []
    else:
        disc = b * b - 4 * a * c
        found = [] if disc < 0 else [(-b - disc**0.5) / (2 * a), (-b + disc**0.5) / (2 * a)]
    return [s for s in found if 0.0 < s < 1.0]


def _hermite(
    path: JointPath, k: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float] | None:
    """(p0, p1, m0, m1, duration) of segment ``k`` when it is cubic, else None."""
    v0, v1 = path.velocities[k], path.velocities[k + 1]
    if np.isnan(v0).any() or np.isnan(v1).any():
        return None
    duration = float(path.times_s[k + 1] - path.times_s[k])
    with np.errstate(over="ignore"):  # a huge velocity: refused by _fastest's ends
        m0, m1 = v0 * duration, v1 * duration
    return path.positions[k], path.positions[k + 1], m0, m1, duration


def _segment_at(path: JointPath, k: int, time_s: float) -> tuple[FloatArray, FloatArray]:
    """(positions, velocities) inside segment ``k`` at ``time_s``."""
    p0, p1 = path.positions[k], path.positions[k + 1]
    duration = float(path.times_s[k + 1] - path.times_s[k])
    s = (time_s - float(path.times_s[k])) / duration
    cubic = _hermite(path, k)
    if cubic is None:
        return p0 + (p1 - p0) * s, (p1 - p0) / duration
    _, _, m0, m1, _ = cubic
    h00, h10, h01, h11 = (
        2 * s**3 - 3 * s**2 + 1,
        s**3 - 2 * s**2 + s,
        -2 * s**3 + 3 * s**2,
        s**3 - s**2,
    )
    d00, d10, d01, d11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, -6 * s**2 + 6 * s, 3 * s**2 - 2 * s
    position = h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1
    velocity = (d00 * p0 + d10 * m0 + d01 * p1 + d11 * m1) / duration
    return position, velocity


def _fastest(path: JointPath, k: int) -> FloatArray:
    """Per joint, the largest |velocity| on segment ``k``: exact for both kinds."""
    p0, p1 = path.positions[k], path.positions[k + 1]
    duration = float(path.times_s[k + 1] - path.times_s[k])
    cubic = _hermite(path, k)
    if cubic is None:
        speed: FloatArray = np.abs(p1 - p0) / duration
        return speed
    # The ends are the knots' own velocities: v·T may overflow for a huge finite v, and
    # NaN would pass every "faster than the limit" test.
    ends = np.maximum(np.abs(path.velocities[k]), np.abs(path.velocities[k + 1]))
    _, _, m0, m1, _ = cubic
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        # q'(s)·T = a s² + b s + c with these coefficients (Hermite basis derivatives)
        a = 6 * p0 + 3 * m0 - 6 * p1 + 3 * m1
        b = -6 * p0 - 4 * m0 + 6 * p1 - 2 * m1
        c = m0
        vertex = np.where(a != 0.0, -b / (2 * a), -1.0)
        inside = (vertex > 0.0) & (vertex < 1.0)  # False where NaN (an overflowed spline)
        peak = np.abs(a * vertex**2 + b * vertex + c) / duration
    fastest: FloatArray = np.where(inside, np.maximum(ends, peak), ends)
    return fastest
