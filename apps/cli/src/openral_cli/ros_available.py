"""One clear error, for every command that needs ROS 2, when the ``ros`` extra is missing."""

from __future__ import annotations

import importlib

from openral_core.errors import OpenralError


def require_ros() -> None:
    """Import rclpy now; without it, raise one error that says what to install.

    Raises:
        OpenralError: rclpy (the ``ros`` extra) cannot be imported.
    """
    try:
        importlib.import_module("rclpy")
    except ImportError as error:
        raise OpenralError(
            f"ROS 2 is not importable ({error}); install the 'ros' extra (pip install "
            "'openral[ros]') or run ./bootstrap"
        ) from None
