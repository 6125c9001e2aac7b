"""sensor_msgs/Image → numpy RGB without cv_bridge (not on PyPI).

The inverse of :func:`openral_bridge.ros_messages.image_msg` for consumers of camera
topics. Supported encodings: ``rgb8``, ``bgr8`` and ``mono8``; row padding (``step``
larger than ``width * channels``) is honoured.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError

CHANNELS = {"rgb8": 3, "bgr8": 3, "mono8": 1}
"""Bytes per pixel of each supported encoding."""


class ImageEncodingError(OpenralError):
    """An Image message this module cannot turn into RGB pixels."""


def image_to_rgb(msg: Any) -> npt.NDArray[np.uint8]:
    """HxWx3 uint8 RGB copy of a sensor_msgs/Image (rgb8, bgr8 or mono8)."""
    channels = CHANNELS.get(msg.encoding)
    if channels is None:
        raise ImageEncodingError(
            f"image encoding {msg.encoding!r} is not supported; expected one of "
            f"{', '.join(CHANNELS)}"
        )
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    row_bytes = width * channels
    buffer = np.frombuffer(msg.data, dtype=np.uint8)
    if step < row_bytes or buffer.size < step * height:
        raise ImageEncodingError(
            f"malformed {msg.encoding} image: {width}x{height}, step {step}, "
            f"{buffer.size} data bytes (need step >= {row_bytes} and {step * height} bytes)"
        )
    rows = buffer[: step * height].reshape(height, step)[:, :row_bytes]
    pixels = rows.reshape(height, width, channels)
    if msg.encoding == "bgr8":
        pixels = pixels[:, :, ::-1]
    elif msg.encoding == "mono8":
        pixels = np.repeat(pixels, 3, axis=2)
    return np.ascontiguousarray(pixels)
