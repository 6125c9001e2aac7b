"""Errors raised by HALs."""

from __future__ import annotations

from openral_core.errors import OpenralError


class HalError(OpenralError):
    """A HAL call that cannot be carried out in the HAL's current state."""


class NotConnected(HalError):
    """A call that needs a connected HAL was made before ``connect()`` or after ``disconnect()``."""


class EStopLatched(HalError):
    """An action was sent while the E-stop is latched; call ``release_estop()`` first."""


class ActionRejected(HalError):
    """An action of the wrong type, width or with a non-finite value; nothing was applied."""


class SimulationDiverged(HalError):
    """MuJoCo met a NaN/Inf acceleration and reset the simulation to its initial state."""


class ConfigurationError(HalError):
    """A HAL cannot be built or connected as configured (mode, scene, driver or action width)."""
