"""Sensor messages → numpy without cv_bridge (not on PyPI) or sensor_msgs_py.

The inverses of :mod:`openral_bridge.ros_messages` for consumers of sensor topics:

- :func:`image_to_rgb`: ``rgb8``, ``bgr8`` and ``mono8`` images;
- :func:`depth_metres`: ``32FC1`` (metres) and ``16UC1`` (millimetres) depth images, and
  :func:`depth_colours` to look at one;
- :func:`cloud_points`: the x, y, z of a ``PointCloud2`` with FLOAT32 fields.

Row padding (``step`` larger than a row) and either byte order are honoured; a message whose
sizes do not add up is refused with one line saying what it holds and what was expected.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError

FLOAT32 = 7
"""``sensor_msgs/PointField.FLOAT32``."""
CHANNELS = {"rgb8": 3, "bgr8": 3, "mono8": 1}
"""Bytes per pixel of each supported encoding."""


class ImageEncodingError(OpenralError):
    """A sensor message this module cannot turn into numbers."""


def image_to_rgb(msg: Any) -> npt.NDArray[np.uint8]:
    """HxWx3 uint8 RGB copy of a sensor_msgs/Image (rgb8, bgr8 or mono8)."""
    channels = CHANNELS.get(msg.encoding)
    if channels is None:
        raise ImageEncodingError(
            f"image encoding {msg.encoding!r} is not supported; expected one of "
            f"{', '.join(CHANNELS)}"
        )
    pixels = _pixel_bytes(msg, channels).reshape(int(msg.height), int(msg.width), channels)
    if msg.encoding == "bgr8":
        pixels = pixels[:, :, ::-1]
    elif msg.encoding == "mono8":
        pixels = np.repeat(pixels, 3, axis=2)
    return np.ascontiguousarray(pixels)


DEPTH_ENCODINGS = {"32FC1": ("f4", 1.0), "16UC1": ("u2", 0.001)}
"""Depth encodings read: item type and metres per unit (16UC1 is millimetres, 0 = none)."""


def depth_metres(msg: Any) -> npt.NDArray[np.float32]:
    """HxW depth [m] of a ``32FC1`` or ``16UC1`` sensor_msgs/Image; NaN where none."""
    kind = DEPTH_ENCODINGS.get(msg.encoding)
    if kind is None:
        raise ImageEncodingError(
            f"depth encoding {msg.encoding!r} is not supported; expected one of "
            f"{', '.join(DEPTH_ENCODINGS)}"
        )
    code, scale = kind
    dtype = np.dtype((">" if msg.is_bigendian else "<") + code)
    rows = _pixel_bytes(msg, dtype.itemsize)
    values = rows.copy().view(dtype).astype(np.float32) * np.float32(scale)
    if code == "u2":
        values[values == 0] = np.nan
    return values.reshape(int(msg.height), int(msg.width))


def _pixel_bytes(msg: Any, pixel_bytes: int) -> npt.NDArray[np.uint8]:
    """H x (W * ``pixel_bytes``) bytes of an Image's rows, its ``step`` padding dropped.

    Raises:
        ImageEncodingError: A step shorter than a row, or fewer bytes than the rows need.
    """
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    row_bytes = width * pixel_bytes
    buffer = np.frombuffer(msg.data, dtype=np.uint8)
    if step < row_bytes or buffer.size < step * height:
        raise ImageEncodingError(
            f"malformed {msg.encoding} image: {width}x{height}, step {step}, "
            f"{buffer.size} data bytes (need step >= {row_bytes} and {step * height} bytes)"
        )
    return buffer[: step * height].reshape(height, step)[:, :row_bytes]


def depth_colours(depth_m: npt.NDArray[np.floating]) -> npt.NDArray[np.uint8]:
    """HxWx3 RGB of a depth image: near is warm, far is cool (a perceptually ordered ramp
    from the image's nearest to its farthest reading), no reading is black."""
    depth = np.asarray(depth_m, dtype=np.float64)
    seen = np.isfinite(depth)
    rgb = np.zeros((*depth.shape, 3), dtype=np.uint8)
    if not seen.any():
        return rgb
    low, high = float(depth[seen].min()), float(depth[seen].max())
    t = (depth[seen] - low) / (high - low) if high > low else np.zeros(int(seen.sum()))
    stops = np.array([[253, 231, 37], [53, 183, 121], [49, 104, 142], [68, 1, 84]], float)
    positions = np.linspace(0.0, 1.0, len(stops))
    rgb[seen] = (
        np.stack([np.interp(t, positions, stops[:, c]) for c in range(3)], axis=1)
        .round()
        .astype(np.uint8)
    )
    return rgb


def cloud_points(msg: Any) -> npt.NDArray[np.float32]:
    """N x 3 x, y, z [m] of a sensor_msgs/PointCloud2 with FLOAT32 x, y, z fields."""
    offsets = {f.name: int(f.offset) for f in msg.fields if int(f.datatype) == FLOAT32}
    missing = [axis for axis in "xyz" if axis not in offsets]
    if missing:
        raise ImageEncodingError(f"point cloud without FLOAT32 field(s) {', '.join(missing)}")
    count, step = int(msg.width) * int(msg.height), int(msg.point_step)
    buffer = np.frombuffer(msg.data, dtype=np.uint8)
    if step < max(offsets[a] for a in "xyz") + 4 or buffer.size < count * step:
        raise ImageEncodingError(
            f"malformed point cloud: {count} points of {step} bytes, {buffer.size} data bytes"
        )
    rows = buffer[: count * step].reshape(count, step)
    order = ">" if msg.is_bigendian else "<"
    columns = [rows[:, offsets[a] : offsets[a] + 4].copy().view(order + "f4") for a in "xyz"]
    return np.concatenate(columns, axis=1).astype(np.float32)
