"""A ROS publisher that lets go of Python's lock while the middleware sends.

rclpy's ``Publisher.publish`` keeps Python's lock for the whole call into the middleware.
Fast DDS (Jazzy's default) can hold a ``write`` for 0.3 s while it matches the endpoints of
a program that has just joined the domain (measured here: ``ros2 topic list``, a policy
runner); every Python thread of the publishing process stops with it. On a real robot that
is the driver's loop: its reading goes stale and the two-period rule latches the E-stop
(:mod:`openral_real.bus_cycle`).

:class:`UnlockedPublisher` is a drop-in ``publisher_class`` for ``Node.create_publisher``:
the message is converted to its C form by its type's own converter (as rclpy
does, holding the lock), then handed to ``rcl_publish`` through :mod:`ctypes`, which
releases the lock for the foreign call; the bytes on the wire are rclpy's own. The
thread that publishes still waits for the middleware; every other thread
(the driver's loop, the executor) runs on.
"""

from __future__ import annotations

import ctypes
import sys
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any, cast

from rclpy.publisher import Publisher

_CREATE = ctypes.CFUNCTYPE(ctypes.c_void_p)
_DESTROY = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
_FROM_PY = ctypes.PYFUNCTYPE(ctypes.c_bool, ctypes.py_object, ctypes.c_void_p)
"""The message type's own converters (rosidl's capsules; converting needs Python's lock)."""


@dataclass(frozen=True)
class _Converters:
    create: Any
    from_py: Any
    destroy: Any


@cache
def _converters(msg_type: type) -> _Converters:
    """The C functions that make, fill and free ``msg_type``'s C message."""
    get = ctypes.pythonapi.PyCapsule_GetPointer
    get.restype, get.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
    kind = type(msg_type)
    kind.__import_type_support__()  # type: ignore[attr-defined]

    def pointer(name: str) -> int:
        return int(get(getattr(kind, name), None))

    return _Converters(
        _CREATE(pointer("_CREATE_ROS_MESSAGE")),
        _FROM_PY(pointer("_CONVERT_FROM_PY")),
        _DESTROY(pointer("_DESTROY_ROS_MESSAGE")),
    )


@cache
def _rcl() -> ctypes.CDLL:
    """rcl's shared library, as rclpy loaded it (the copy beside the interpreter's prefix
    when the loader does not know it by name)."""
    try:
        library = ctypes.CDLL("librcl.so")
    except OSError:
        library = ctypes.CDLL(str(Path(sys.prefix) / "lib" / "librcl.so"))
    library.rcl_publish.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]
    library.rcl_publish.restype = ctypes.c_int
    library.rcutils_get_error_string.restype = _ErrorString  # returned by value
    return library


class _ErrorString(ctypes.Structure):
    """``rcutils_error_string_t`` (a struct of one 1024-byte string: an array return type
    would crash ctypes)."""

    _fields_ = [("text", ctypes.c_char * 1024)]


def rcl_error(code: int) -> str:
    """rcl's error text for a call that returned ``code``, and the error state reset."""
    library = _rcl()
    text = library.rcutils_get_error_string().text.decode(errors="replace")
    library.rcutils_reset_error()
    return text if text and text != "error not set" else f"rcl {code}"


class UnlockedPublisher(Publisher):
    """``Publisher`` whose :meth:`publish` releases Python's lock (see the module doc)."""

    def publish(self, msg: Any) -> None:
        """Send ``msg`` (an instance of the publisher's type).

        Raises:
            TypeError: ``msg`` is not of the publisher's type.
            RuntimeError: rcl refused it (its error text, naming the topic).
        """
        kind = cast(type, self.msg_type)
        if not isinstance(msg, kind):
            raise TypeError(f"Expected {self.msg_type}, got {type(msg)}")
        convert = _converters(kind)
        message = convert.create()
        if not message:
            raise MemoryError(f"{self.topic_name}: no memory for a {kind.__name__} message")
        try:
            if not convert.from_py(msg, message):
                raise TypeError(f"{self.topic_name}: the {kind.__name__} does not convert")
            library = _rcl()
            with self.handle:
                code = library.rcl_publish(self.handle.pointer, message, None)  # lock let go
        finally:
            convert.destroy(message)
        if code != 0:
            raise RuntimeError(f"{self.topic_name}: publish failed ({rcl_error(code)})")
