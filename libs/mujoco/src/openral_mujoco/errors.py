"""Errors of the robot contract that the MuJoCo layer itself enforces.

The HAL package adds its lifecycle errors (not connected, E-stop, configuration) under the
same :class:`HalError` base, so one ``except HalError`` catches any refused robot call.
"""

from __future__ import annotations

from openral_core.errors import OpenralError


class HalError(OpenralError):
    """A robot call that cannot be carried out in its current state."""


class ActionRejected(HalError):
    """An action of the wrong type, width or with a non-finite value; nothing was applied."""


class SimulationDiverged(HalError):
    """MuJoCo met a NaN/Inf acceleration and reset the simulation to its initial state."""


class TreeUnsupported(HalError):
    """The model has a joint or body layout a URDF tree cannot state; the message says where."""
