"""The envelope every goal passes on its way to a real arm's motors, in joint radians.

- A command (the **target**) is clamped into the joints' position limits first (each
  clamped joint counted).
- The **goal** written to the motors starts where the arm is measured (:meth:`start`: at
  connect and at an E-stop release), so nothing jumps, and moves towards the target by at
  most ``velocity_limit x period`` per control period (:meth:`step`), so no command is
  faster than the manifest allows, whatever a client sends.
- Until the goal has caught up with the target once, the first motion moves at
  ``first_motion_speed_scale`` of that speed.

Thread-safe: clients aim from any thread, the bus cycle steps on its own.
"""

from __future__ import annotations

import threading

import numpy as np
from openral_mujoco.state import FloatArray


class MotionEnvelope:
    """Position clamp, velocity slew and a slow first motion (see the module doc)."""

    def __init__(
        self,
        low: FloatArray,
        high: FloatArray,
        velocity_limit: FloatArray,
        period_s: float,
        first_motion_scale: float,
    ) -> None:
        """Limits per joint [rad], velocity limits [rad/s], the control period [s] and the
        first motion's share of the velocity limits (0 < scale <= 1)."""
        self.low, self.high = np.asarray(low, float), np.asarray(high, float)
        self.max_step = np.asarray(velocity_limit, float) * float(period_s)
        self.first_motion_scale = float(first_motion_scale)
        self.clamped = np.zeros(len(self.low), dtype=np.int64)
        """Commands clamped into the position limits, per joint."""
        self._lock = threading.Lock()
        self._goal = np.clip(np.zeros(len(self.low)), self.low, self.high)
        self._target = self._goal.copy()
        self._first = True

    @property
    def goal(self) -> FloatArray:
        """The goal last stepped to [rad] (a copy)."""
        with self._lock:
            return self._goal.copy()

    @property
    def target(self) -> FloatArray:
        """The clamped command the goal moves towards [rad] (a copy)."""
        with self._lock:
            return self._target.copy()

    @property
    def first_motion(self) -> bool:
        """True until the goal has caught up with the target once since :meth:`start`."""
        with self._lock:
            return self._first

    def start(self, measured: FloatArray) -> None:
        """Goal and target ← the measured joints (held as they are); the first motion
        is slow again."""
        with self._lock:
            self._goal = np.asarray(measured, float).copy()
            self._target = np.clip(self._goal, self.low, self.high)
            self._first = True

    def aim(self, target: FloatArray) -> None:
        """Move towards ``target`` [rad] from now on (clamped into the limits)."""
        wanted = np.asarray(target, float)
        clamped = np.clip(wanted, self.low, self.high)
        with self._lock:
            self.clamped += clamped != wanted
            self._target = clamped

    def step(self) -> FloatArray:
        """The next goal: one control period closer to the target, no faster than allowed."""
        with self._lock:
            scale = self.first_motion_scale if self._first else 1.0
            limit = self.max_step * scale
            self._goal = self._goal + np.clip(self._target - self._goal, -limit, limit)
            if self._first and np.array_equal(self._goal, self._target):
                self._first = False
            return self._goal.copy()
