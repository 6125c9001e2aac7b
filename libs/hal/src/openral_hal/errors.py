"""Errors raised by HALs: the contract's own (re-exported) plus the HAL lifecycle's."""

from __future__ import annotations

from openral_mujoco.errors import ActionRejected, HalError, SimulationDiverged

__all__ = [
    "ActionRejected",
    "ConfigurationError",
    "EStopLatched",
    "HalError",
    "NotConnected",
    "SimulationDiverged",
]


class NotConnected(HalError):
    """A call that needs a connected HAL was made before ``connect()`` or after ``disconnect()``."""


class EStopLatched(HalError):
    """An action was sent while the E-stop is latched; call ``release_estop()`` first."""

    def __init__(
        self, message: str = "E-stop is latched; call release_estop() before sending actions"
    ) -> None:
        super().__init__(message)


class ConfigurationError(HalError):
    """A HAL cannot be built or connected as configured (mode, scene, driver or action width)."""
