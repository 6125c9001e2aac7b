"""One clear error, for every command that needs ROS 2, when the ``ros`` extra is missing."""

from __future__ import annotations

import importlib
import sys

from openral_core.errors import OpenralError

CODE_GENERATOR = "rosidl_generator_py.generate_py_impl"
"""The message code generator that ``rosidl_generator_py``'s ``__init__`` imports whenever a
message's type support loads (lark, empy, rosidl_parser: ~12 ms with cached bytecode, ~0.14 s
without). A command runs generated messages and never generates any, so it is not loaded."""


def require_ros() -> None:
    """Import rclpy now; without it, raise one error that says what to install.

    Also keeps the message code generator out of the process (:data:`CODE_GENERATOR`): its
    package then takes its own "cannot generate" path, which logs at debug level only.

    Raises:
        OpenralError: rclpy (the ``ros`` extra) cannot be imported.
    """
    sys.modules.setdefault(CODE_GENERATOR, None)  # type: ignore[arg-type]
    try:
        importlib.import_module("rclpy")
    except ImportError as error:
        raise OpenralError(
            f"ROS 2 is not importable ({error}); install the 'ros' extra (pip install "
            "'openral[ros]') or run ./bootstrap"
        ) from None
