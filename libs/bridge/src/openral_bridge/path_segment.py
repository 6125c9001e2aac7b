"""One segment of a joint path between two knots: a straight line, or a cubic Hermite spline
when both knots carry velocities.

With ``s = (t - t0) / T`` in [0, 1] and ``m = v·T``, a cubic segment is
``q(s) = h00 p0 + h10 m0 + h01 p1 + h11 m1`` (the Hermite basis), so its speed
``q'(s)/T`` is a quadratic in ``s``: its largest value on the segment and its turning
points (where a cubic may bulge past its knots) are found exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from openral_mujoco.state import FloatArray


@dataclass(frozen=True)
class Segment:
    """Positions and velocities (NaN: none given) of the two knots of a segment, per joint."""

    p0: FloatArray
    p1: FloatArray
    v0: FloatArray
    v1: FloatArray
    t0: float
    t1: float

    @property
    def duration(self) -> float:
        """Its length in time [s]."""
        return self.t1 - self.t0

    @property
    def tangents(self) -> tuple[FloatArray, FloatArray] | None:
        """(m0, m1) = knot velocities times the duration when it is cubic, else None."""
        if np.isnan(self.v0).any() or np.isnan(self.v1).any():
            return None
        with np.errstate(over="ignore"):  # a huge velocity: refused by fastest()'s ends
            return self.v0 * self.duration, self.v1 * self.duration

    def at(self, time_s: float) -> tuple[FloatArray, FloatArray]:
        """(positions, velocities) at ``time_s`` inside the segment."""
        p0, p1, duration = self.p0, self.p1, self.duration
        s = (time_s - self.t0) / duration
        cubic = self.tangents
        if cubic is None:
            return p0 + (p1 - p0) * s, (p1 - p0) / duration
        m0, m1 = cubic
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
        d00, d10 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1
        d01, d11 = -6 * s**2 + 6 * s, 3 * s**2 - 2 * s
        position = h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1
        velocity = (d00 * p0 + d10 * m0 + d01 * p1 + d11 * m1) / duration
        return position, velocity

    def speed_coefficients(self, m0: FloatArray, m1: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(a, b) of ``q'(s)·T = a s² + b s + m0``."""
        p0, p1 = self.p0, self.p1
        return 6 * p0 + 3 * m0 - 6 * p1 + 3 * m1, -6 * p0 - 4 * m0 + 6 * p1 - 2 * m1

    def fastest(self) -> FloatArray:
        """Per joint, the largest |velocity| on the segment: exact for both kinds."""
        cubic = self.tangents
        if cubic is None:
            speed: FloatArray = np.abs(self.p1 - self.p0) / self.duration
            return speed
        # The ends are the knots' own velocities: v·T may overflow for a huge finite v, and
        # NaN would pass every "faster than the limit" test.
        ends = np.maximum(np.abs(self.v0), np.abs(self.v1))
        m0, m1 = cubic
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            a, b = self.speed_coefficients(m0, m1)
            vertex = np.where(a != 0.0, -b / (2 * a), -1.0)
            inside = (vertex > 0.0) & (vertex < 1.0)  # False where NaN (an overflowed spline)
            peak = np.abs(a * vertex**2 + b * vertex + m0) / self.duration
        fastest: FloatArray = np.where(inside, np.maximum(ends, peak), ends)
        return fastest

    def turning_points(self, joint: int) -> list[tuple[float, float]]:
        """(time [s], position) of each turning point of a cubic segment's ``joint`` strictly
        inside the segment (none for a line)."""
        cubic = self.tangents
        if cubic is None:
            return []
        m0, m1 = cubic
        a, b = self.speed_coefficients(m0, m1)
        p0, p1, n0, n1 = self.p0[joint], self.p1[joint], m0[joint], m1[joint]
        points = []
        for s in roots(float(a[joint]), float(b[joint]), float(n0)):
            q = (2 * s**3 - 3 * s**2 + 1) * p0 + (s**3 - 2 * s**2 + s) * n0
            q += (-2 * s**3 + 3 * s**2) * p1 + (s**3 - s**2) * n1
            points.append((self.t0 + s * self.duration, float(q)))
        return points


def roots(a: float, b: float, c: float) -> list[float]:
    """Roots of a s² + b s + c inside (0, 1)."""
    if a == 0.0:
        found = [-c / b] if b != 0.0 else []
    else:
        disc = b * b - 4 * a * c
        found = [] if disc < 0 else [(-b - disc**0.5) / (2 * a), (-b + disc**0.5) / (2 * a)]
    return [s for s in found if 0.0 < s < 1.0]
