"""CameraMessages: one camera's ``Image`` and ``CameraInfo``, reused frame after frame.

A camera publishes the same kind of message at every frame: only the pixels and the stamp
change (and the sizes, should a backend change its image size). Building an ``Image`` from
a numpy frame the usual way copies the pixels twice (``tobytes``, then into the message's
``array``) into freshly allocated memory, and a freshly built ``CameraInfo`` converts its
matrices again; at 640x480 that was 1-2 ms of CPU per frame on the 2-core development
machine. Here the ``Image`` keeps one ``array('B')`` of the frame's size, :meth:`pixels`
exposes it as an H x W x 3 array a renderer draws straight into
(``mujoco.Renderer.render(out=...)``), and the ``CameraInfo`` is built once per size.

Use one instance from one thread at a time (a camera has at most one frame in flight);
``publish`` converts the message before it returns, so the buffer is free again then.
"""

from __future__ import annotations

import array
from typing import Any

import numpy as np
import numpy.typing as npt
from sensor_msgs.msg import Image

from openral_bridge import ros_messages

ImageArray = npt.NDArray[np.uint8]


class CameraMessages:
    """The reusable messages of one RGB camera (``rgb8``)."""

    def __init__(self, frame_id: str, fovy_deg: float | None) -> None:
        """Nothing is allocated until the first frame.

        Args:
            frame_id: The header's frame id.
            fovy_deg: Vertical field of view [deg]; None: no ``CameraInfo``.
        """
        self.frame_id = frame_id
        self.fovy_deg = fovy_deg
        self._image: Any = None
        self._pixels: ImageArray | None = None
        self._info: Any = None

    def pixels(self, height: int, width: int) -> ImageArray:
        """The next ``Image``'s data as a writable H x W x 3 uint8 array [px]; (re)allocated
        when the size changes, else the same array as last time."""
        if self._pixels is None or self._pixels.shape[:2] != (height, width):
            image = Image()
            image.header.frame_id = self.frame_id
            image.height, image.width, image.encoding = height, width, "rgb8"
            image.is_bigendian = 0
            image.step = width * 3
            image.data = array.array("B", bytes(height * width * 3))
            self._image = image
            self._pixels = np.frombuffer(image.data, np.uint8).reshape(height, width, 3)
            self._info = None
            if self.fovy_deg is not None:
                stamp = ros_messages.stamp(0.0)
                info = ros_messages.camera_info_msg(width, height, self.fovy_deg, stamp, "")
                info.header.frame_id = self.frame_id
                self._info = info
        return self._pixels

    def fill(self, frame: ImageArray) -> None:
        """Copy an H x W x 3 uint8 ``frame`` into :meth:`pixels` (nothing to do when the frame
        was drawn there).

        Raises:
            ValueError: Any other shape or dtype.
        """
        if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype != np.uint8:
            raise ValueError(
                f"frame of shape {frame.shape} and dtype {frame.dtype}; "
                "expected H x W x 3 uint8 (rgb8)"
            )
        height, width = frame.shape[:2]
        pixels = self.pixels(height, width)
        if frame is not pixels:
            np.copyto(pixels, frame)

    def stamped(self, stamp: Any) -> tuple[Any, Any | None]:
        """The ``Image`` holding :meth:`pixels` and the ``CameraInfo`` (None without a field
        of view), both stamped ``stamp``.

        Raises:
            RuntimeError: No frame yet (:meth:`pixels` or :meth:`fill` first).
        """
        if self._image is None:
            raise RuntimeError("no frame yet: draw into pixels() or fill() first")
        self._image.header.stamp = stamp
        if self._info is not None:
            self._info.header.stamp = stamp
        return self._image, self._info
