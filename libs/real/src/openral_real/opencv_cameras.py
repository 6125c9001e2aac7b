"""A real robot's RGB cameras, read with OpenCV.

Each RGB sensor that names a device (its manifest ``device`` or a ``--camera NAME=DEVICE``
override) gets a reader thread: a camera index (``0``), a V4L2 path (``/dev/video0``) or a
video file (``file:clip.mp4``, played at the sensor's rate and looped, for tests and
rehearsals). Frames are turned to RGB and scaled to the sensor's width x height; the newest
one is what :meth:`Cameras.frames` hands out, so the graph publishes and feeds VLA slots
exactly as it does a simulated camera's. A device that cannot be opened, or gives no first
frame, stops the bring-up with one line naming the sensor and the device.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
from openral_core.models import RgbSensor

from openral_real.errors import BusError

ImageArray = npt.NDArray[np.uint8]
FIRST_FRAME_S = 5.0
"""Longest wait for a device's first frame at bring-up [s]."""


class CameraError(BusError):
    """A camera device cannot be opened or gives no frames."""


def camera_devices(
    sensors: Mapping[str, RgbSensor], overrides: Mapping[str, str]
) -> dict[str, str]:
    """Sensor → device for every RGB sensor with one (an override wins).

    Raises:
        CameraError: An override names no RGB sensor of the robot.
    """
    unknown = sorted(set(overrides) - set(sensors))
    if unknown:
        raise CameraError(
            f"--camera {unknown[0]}=...: no RGB sensor {unknown[0]!r}; the robot's RGB "
            f"sensors: {', '.join(sensors) or 'none'}"
        )
    found = {name: sensor.device for name, sensor in sensors.items() if sensor.device}
    return {**found, **overrides}


class _Reader:
    """One device on a thread of its own, keeping its newest frame."""

    def __init__(self, sensor: RgbSensor, device: str) -> None:
        self.sensor, self.device = sensor, device
        self.is_file = device.startswith("file:")
        source: int | str = int(device) if device.isdigit() else device.removeprefix("file:")
        if self.is_file and not Path(str(source)).is_file():
            raise CameraError(f"camera {sensor.name}: no video file {source}")
        if isinstance(source, str) and source.startswith("/dev/") and not Path(source).exists():
            raise CameraError(f"camera {sensor.name}: cannot open {device} (no such device)")
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)  # one line: ours
        self.capture = cv2.VideoCapture(source)
        if not self.capture.isOpened():
            raise CameraError(
                f"camera {sensor.name}: cannot open {device} (is it plugged in, and not held "
                "by another program?)"
            )
        self.frame: ImageArray | None = None
        self.frames = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"camera-{sensor.name}", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        self.capture.release()

    def _run(self) -> None:
        period = 1.0 / self.sensor.rate_hz
        due = time.monotonic()
        while not self._stop.is_set():
            ok, image = self.capture.read()
            if not ok and self.is_file:  # the end of a clip: play it again
                self.capture.set(cv2.CAP_PROP_POS_FRAMES, 0)
                ok, image = self.capture.read()
            if not ok:
                self._stop.wait(period)
                continue
            size = (self.sensor.width, self.sensor.height)
            rgb = cv2.cvtColor(
                cv2.resize(image, size, interpolation=cv2.INTER_AREA), cv2.COLOR_BGR2RGB
            )
            self.frame, self.frames = np.ascontiguousarray(rgb), self.frames + 1
            if self.is_file:  # a live camera paces itself; a file plays at the sensor's rate
                due += period
                self._stop.wait(max(0.0, due - time.monotonic()))


class Cameras:
    """The readers of one robot's cameras (see the module doc)."""

    def __init__(self, sensors: Mapping[str, RgbSensor], devices: Mapping[str, str]) -> None:
        """Nothing is opened until :meth:`open`."""
        self.sensors, self.devices = dict(sensors), dict(devices)
        self._readers: dict[str, _Reader] = {}

    def open(self) -> None:
        """Open every device and wait for its first frame.

        Raises:
            CameraError: A device cannot be opened or sends nothing (the others are closed).
        """
        try:
            for name, device in self.devices.items():
                reader = _Reader(self.sensors[name], device)
                self._readers[name] = reader
                reader.start()
            for name, reader in self._readers.items():
                deadline = time.monotonic() + FIRST_FRAME_S
                while reader.frame is None and time.monotonic() < deadline:
                    time.sleep(0.01)
                if reader.frame is None:
                    raise CameraError(
                        f"camera {name}: {reader.device} sent no frame within {FIRST_FRAME_S:g} s"
                    )
        except CameraError:
            self.close()
            raise

    def close(self) -> None:
        """Stop every reader (idempotent)."""
        readers, self._readers = self._readers, {}
        for reader in readers.values():
            reader.stop()

    def frames(self) -> dict[str, ImageArray]:
        """The newest frame of each camera (H x W x 3 RGB), by sensor name."""
        return {name: r.frame for name, r in self._readers.items() if r.frame is not None}
