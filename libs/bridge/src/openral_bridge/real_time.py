"""Is the simulation keeping up with the wall clock? The real-time factor over a window.

The control loop ticks on a wall-clock timer and never runs ahead of real time; when the
machine is too slow, ticks are late or skipped and simulated time falls behind. This watch
compares the two over windows of :data:`WINDOW_S` and speaks once when a whole window ran
below :data:`SLOW_FACTOR`, then again only after the loop has caught up.
"""

from __future__ import annotations

WINDOW_S = 5.0
"""Length of one measurement window [s of wall time]."""
SLOW_FACTOR = 0.95
"""A window whose simulated time advanced less than this fraction of its wall time is slow."""


class RealTimeWatch:
    """Real-time factor per window; reports the first slow window of each slow spell."""

    def __init__(self, window_s: float = WINDOW_S, slow_factor: float = SLOW_FACTOR) -> None:
        self.window_s = window_s
        self.slow_factor = slow_factor
        self.factor: float | None = None
        """Real-time factor of the last complete window (None before the first)."""
        self._start: tuple[float, float] | None = None
        self._spoke = False

    def update(self, wall_s: float, sim_s: float) -> float | None:
        """Record the clocks now; returns the factor when this call ends the first slow
        window of a spell (say it once), else None.

        Args:
            wall_s: A monotonic wall clock [s].
            sim_s: Simulated time [s].
        """
        if self._start is None or sim_s < self._start[1]:  # first call, or the scene reset
            self._start = (wall_s, sim_s)
            return None
        wall0, sim0 = self._start
        if wall_s - wall0 < self.window_s:
            return None
        self.factor = (sim_s - sim0) / (wall_s - wall0)
        self._start = (wall_s, sim_s)
        if self.factor >= self.slow_factor:
            self._spoke = False
            return None
        if self._spoke:
            return None
        self._spoke = True
        return self.factor

    def restart(self) -> None:
        """Forget the window (after a pause the loop did on purpose, such as an E-stop)."""
        self._start = None
