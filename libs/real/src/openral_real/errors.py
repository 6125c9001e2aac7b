"""Errors of the real-robot drivers: each says what is wrong and what to do, in one line."""

from __future__ import annotations

from openral_hal.errors import ConfigurationError, HalError


class BusError(ConfigurationError):
    """The servo bus cannot be used: no such port, a busy port, a motor that does not
    answer or is not the expected model. Raised before anything is written to the bus."""


class CalibrationError(ConfigurationError):
    """A calibration file is missing, unreadable or belongs to another arm."""


class BusFault(HalError):
    """The bus failed while running (a silent motor, a corrupt reply, a servo fault, the
    port gone); the driver latches its E-stop with this as the reason."""
