"""The manifest node's parameters: names, defaults, and the ranges checked at configure."""

from __future__ import annotations

import math
from typing import Any

PARAMETERS: dict[str, Any] = {
    "robot_id": "",
    "manifest_path": "",
    "hal_mode": "sim",
    "sim_env_yaml": "",
    "viewer_enabled": True,
    "camera_publish_rate_hz": 0.0,
    "joint_state_rate_hz": 50.0,
}
"""Every parameter and its default."""

RATE_RANGE_HZ = (0.1, 1000.0)
"""Accepted ``camera_publish_rate_hz`` (or 0) and ``joint_state_rate_hz``, inclusive [Hz]."""
BOUNDS: dict[str, tuple[tuple[float, float], str]] = {
    "camera_publish_rate_hz": (RATE_RANGE_HZ, "Hz"),
    "joint_state_rate_hz": (RATE_RANGE_HZ, "Hz"),
}
"""Range and unit of each bounded parameter, checked at configure."""
UNSET = {"camera_publish_rate_hz": 0.0}
"""Parameters whose value here means "not set" rather than a value to check."""


def check_rates(values: dict[str, Any]) -> None:
    """Check each bounded parameter's value against :data:`BOUNDS`.

    Raises:
        ValueError: A value outside its range (or not finite), naming the range.
    """
    for name, value in values.items():
        (low, high), unit = BOUNDS[name]
        number = float(value)
        if name in UNSET and number == UNSET[name]:
            continue
        if not (math.isfinite(number) and low <= number <= high):
            unset = f" (or {UNSET[name]:g} for each sensor's own rate)" if name in UNSET else ""
            raise ValueError(
                f"parameter {name} must be within {low:g}-{high:g} {unit}{unset}, got {number:g}"
            )
