"""How an emulated servo moves its shaft's set point towards its goal.

A position servo does not jump to a new goal: it runs a speed-limited (and, with an
Acceleration register above 0, acceleration-limited) profile towards it, and the motor's
position loop follows that profile. :class:`ServoProfile` is that profile, in encoder steps;
the simulated joint is then driven to the profile's set point each physics step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

ACCELERATION_UNIT = 100.0
"""Steps/s² per unit of the Acceleration register (0: no acceleration limit)."""


@dataclass
class ServoProfile:
    """The set point of one servo [steps] and its speed [steps/s]."""

    setpoint: float
    speed: float = 0.0

    def follow(self, goal: float, dt_s: float, max_speed: float, acceleration: int) -> float:
        """Advance the set point ``dt_s`` towards ``goal`` and return it.

        Args:
            goal: The goal position [steps].
            dt_s: Time advanced [s].
            max_speed: Highest speed [steps/s] (the Goal_Velocity, else the model's).
            acceleration: The Acceleration register (0: reach ``max_speed`` at once).
        """
        error = goal - self.setpoint
        if error == 0.0 and self.speed == 0.0:
            return self.setpoint
        limit = math.inf if acceleration <= 0 else acceleration * ACCELERATION_UNIT
        reachable = max_speed if math.isinf(limit) else math.sqrt(2.0 * limit * abs(error))
        wanted = math.copysign(min(max_speed, reachable), error)
        if not math.isinf(limit):
            step = limit * dt_s
            wanted = min(max(wanted, self.speed - step), self.speed + step)
        moved = wanted * dt_s
        if abs(moved) >= abs(error) and math.copysign(1.0, moved) == math.copysign(1.0, error):
            self.setpoint, self.speed = goal, 0.0
        else:
            self.setpoint += moved
            self.speed = wanted
        return self.setpoint

    def hold(self, at: float | None = None) -> None:
        """Stop the set point (at ``at`` [steps] when given, where a hand put the shaft)."""
        self.speed = 0.0
        if at is not None:
            self.setpoint = at
