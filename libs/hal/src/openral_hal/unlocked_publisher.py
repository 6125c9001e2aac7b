"""A ROS publisher that lets go of Python's lock while the middleware sends.

rclpy's ``Publisher.publish`` keeps Python's lock for the whole call into the middleware.
Fast DDS (Jazzy's default) can hold a ``write`` for 0.3 s while it matches the endpoints of
a program that has just joined the domain (measured here: ``ros2 topic list``, a policy
runner); every Python thread of the publishing process stops with it. On a real robot that
is the driver's loop: its reading goes stale and the two-period rule latches the E-stop
(:mod:`openral_real.bus_cycle`).

:class:`UnlockedPublisher` is a drop-in ``publisher_class`` for ``Node.create_publisher``:
the message is serialised in Python (as rclpy does), then handed to
``rcl_publish_serialized_message`` through :mod:`ctypes`, which releases the lock for the
foreign call. The thread that publishes still waits for the middleware; every other thread
(the driver's loop, the executor) runs on.
"""

from __future__ import annotations

import ctypes
import sys
from functools import cache
from pathlib import Path
from typing import Any, cast

from rclpy.publisher import Publisher
from rclpy.serialization import serialize_message


class _Allocator(ctypes.Structure):
    """``rcutils_allocator_t`` (unused by a publish; present for the layout)."""

    _fields_ = [
        ("allocate", ctypes.c_void_p),
        ("deallocate", ctypes.c_void_p),
        ("reallocate", ctypes.c_void_p),
        ("zero_allocate", ctypes.c_void_p),
        ("state", ctypes.c_void_p),
    ]


class _SerializedMessage(ctypes.Structure):
    """``rcl_serialized_message_t`` (``rcutils_uint8_array_t``)."""

    _fields_ = [
        ("buffer", ctypes.c_void_p),
        ("buffer_length", ctypes.c_size_t),
        ("buffer_capacity", ctypes.c_size_t),
        ("allocator", _Allocator),
    ]


@cache
def _rcl() -> ctypes.CDLL:
    """rcl's shared library, as rclpy loaded it (the copy beside the interpreter's prefix
    when the loader does not know it by name)."""
    try:
        library = ctypes.CDLL("librcl.so")
    except OSError:
        library = ctypes.CDLL(str(Path(sys.prefix) / "lib" / "librcl.so"))
    publish = library.rcl_publish_serialized_message
    publish.argtypes = [ctypes.c_void_p, ctypes.POINTER(_SerializedMessage), ctypes.c_void_p]
    publish.restype = ctypes.c_int
    library.rcutils_get_error_string.restype = ctypes.c_char * 1024
    return library


class UnlockedPublisher(Publisher):
    """``Publisher`` whose :meth:`publish` releases Python's lock (see the module doc)."""

    def publish(self, msg: Any) -> None:
        """Send ``msg`` (an instance of the publisher's type; raw bytes are sent as they
        are, already serialised).

        Raises:
            TypeError: ``msg`` is not of the publisher's type.
            RuntimeError: rcl refused it (its error text, naming the topic).
        """
        if isinstance(msg, bytes):
            data = msg
        elif isinstance(msg, cast(type, self.msg_type)):
            data = serialize_message(msg)
        else:
            raise TypeError(f"Expected {self.msg_type}, got {type(msg)}")
        payload = ctypes.c_char_p(data)  # points into ``data``: no copy
        message = _SerializedMessage(
            ctypes.cast(payload, ctypes.c_void_p), len(data), len(data), _Allocator()
        )
        library = _rcl()
        with self.handle:
            code = library.rcl_publish_serialized_message(
                self.handle.pointer, ctypes.byref(message), None
            )
        if code != 0:
            text = library.rcutils_get_error_string().value.decode(errors="replace")
            library.rcutils_reset_error()
            raise RuntimeError(f"{self.topic_name}: publish failed ({text or f'rcl {code}'})")
