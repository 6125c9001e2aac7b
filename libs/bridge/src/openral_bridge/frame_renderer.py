"""FrameRenderer: frames of costly sensors (cameras, depth), developed off the control path.

The control loop steps the live state on the node's pacer thread; a camera frame takes
milliseconds to tens of milliseconds to render (llvmpipe, software EGL), so a frame is
never rendered there. When a sensor is due, :meth:`FrameRenderer.request` (called on the
pacer thread holding the HAL's lock, between two control ticks, so the state is consistent)
takes the sensor's snapshot (:meth:`FrameCapture.snapshot
<openral_sim.sensor_sources.FrameCapture.snapshot>`: a MuJoCo scene copies its data, see
:mod:`openral_sim.mujoco_capture`) and returns. One render thread opens the capture's
developer (on that thread: an EGL context is current on one thread only), develops each
snapshot and hands the frame and the snapshot's time to the publish callback. The render
thread never reads the live state.

Each camera has one slot. A camera that is due while its previous frame is still waiting
or rendering is skipped and counted (:attr:`FrameRenderer.skipped`); nothing queues beyond
one frame per camera, so a slow renderer lowers the frame rate, never the control rate.

GIL: measured on the 2-core development machine (MuJoCo 3.8.1, llvmpipe), a pure-Python
loop on the main thread while another thread rendered the Panda tabletop at 640x480
(100-140 ms per frame under load) kept 60-100 % of its iteration rate, and its longest
stall was 16-36 ms, never a whole frame (the loop alone stalled up to 7-19 ms on the shared
machine). ``Renderer.render()`` therefore releases the GIL while ``mjr_render`` and
``mjr_readPixels`` run; what remains is competition for the two cores with llvmpipe's
threads, and the render thread's short Python parts (building and publishing the message):
with two 128x128 cameras rendering at 10 Hz, a request's longest wait for the GIL was
about 4 ms (Python's switch interval is 5 ms). Were the render to hold the GIL, this design
would still bound the control loop's delay to one render, since one thread renders one
frame at a time.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Generic, TypeVar

from openral_hal.realtime import behind_ordinary_programs
from openral_sim.observation import ImageArray
from openral_sim.sensor_sources import FrameCapture, FrameDeveloper

from openral_bridge.os_thread import name_os_thread

__all__ = ["FrameRenderer", "ImageArray", "SnapshotGate", "renderers_opened"]

FrameT = TypeVar("FrameT")
"""What one render makes: an RGB image, a depth frame with its cloud."""
PublishFn = Callable[[str, FrameT, float], None]
"""Publish one sensor's frame with the snapshot's simulated time [s] (render thread)."""

SnapshotGate = Callable[[], float]
"""Asked holding the HAL's lock before a paced snapshot: 0 when the live state may be
taken now, else how long until it may [s] (:mod:`openral_bridge.snapshot_gate`)."""

RETRY_S = 0.01
"""How soon a sensor's job asks again for a frame refused because the previous one is
still in flight [s] (see :mod:`openral_bridge.pacer`: never past the next due time)."""
STOP_TIMEOUT_S = 5.0
"""Longest wait for the render thread to finish its frame when stopping [s]."""

_OPENING: set[int] = set()
"""The render threads started whose renderer is still being made (by ``id``)."""
_OPENED = threading.Condition()


def renderers_opened(timeout_s: float) -> bool:
    """Wait until every started render thread has made its renderer (or failed to).

    Making one holds Python's lock for about 80 ms (MuJoCo 3.8, llvmpipe): a real driver's
    loop starts after it, so that no loop is stalled past its deadline by one (issue 41).

    Returns:
        True when none is still being made; False after ``timeout_s`` [s].
    """
    with _OPENED:
        return _OPENED.wait_for(lambda: not _OPENING, timeout_s)


class _Slot:
    """One sensor's frame in flight."""

    def __init__(self, sensor: str) -> None:
        self.sensor = sensor
        self.time_s = 0.0
        """Time of its snapshot [s]."""
        self.busy = False
        """True from the request until its frame is published (or failed)."""
        self.rendered = 0
        self.skipped = 0


class FrameRenderer(Generic[FrameT]):
    """Snapshots taken on the caller's thread, rendered and published on one thread of
    its own; at most one frame per sensor in flight. Frames are RGB images for cameras
    (``FrameRenderer[ImageArray]``) or whatever the capture develops (a depth frame)."""

    def __init__(
        self,
        capture: FrameCapture[FrameT],
        publish: PublishFn[FrameT],
        *,
        name: str = "openral-render",
    ) -> None:
        """Nothing runs until :meth:`start`.

        Args:
            capture: Snapshots of the live source and their developer.
            publish: Receives each frame and its snapshot's time [s], on the render thread.
            name: The render thread's name (also in the OS, at most 15 bytes there).
        """
        self._capture = capture
        self._publish = publish
        self._slots = {sensor: _Slot(sensor) for sensor in capture.sensors}
        self._jobs: queue.SimpleQueue[_Slot | None] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._idle = threading.Condition(self._lock)
        """Notified whenever a frame leaves flight."""
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._stopping = False
        self.error: BaseException | None = None
        """What stopped the render thread (the renderer or a publish failed), else None."""

    # -- caller's thread --------------------------------------------------------------------

    @property
    def sensors(self) -> tuple[str, ...]:
        """The cameras this renderer serves."""
        return tuple(self._slots)

    @property
    def running(self) -> bool:
        """True while the render thread runs (started, not stopped, no error)."""
        return self._thread.is_alive() and not self._stopping and self.error is None

    @property
    def rendered(self) -> dict[str, int]:
        """Frames published so far, by sensor."""
        return {name: slot.rendered for name, slot in self._slots.items()}

    @property
    def skipped(self) -> dict[str, int]:
        """Requests skipped because that camera's previous frame was still in flight."""
        return {name: slot.skipped for name, slot in self._slots.items()}

    def start(self) -> None:
        """Start the render thread (it creates its renderer first: see
        :func:`renderers_opened`)."""
        with _OPENED:
            _OPENING.add(id(self))
        self._thread.start()

    def request(self, sensor: str, *, wait_s: float = 0.0) -> bool:
        """Snapshot the live data for one frame of ``sensor`` and hand it to the thread.

        Call it where nothing steps the live data (holding the HAL's lock, between ticks).

        Args:
            sensor: The camera.
            wait_s: How long to wait for the previous frame of ``sensor`` to leave flight
                [s] (0: skip at once; a frame that must not be missed, after a reset, waits).

        Returns:
            True when a frame was queued; False when the previous frame of ``sensor`` is
            still in flight (counted in :attr:`skipped`) or the renderer is not running.

        Raises:
            KeyError: ``sensor`` is not one of :attr:`sensors`.
        """
        slot = self._slots[sensor]
        if self._stopping or self.error is not None:
            return False
        with self._lock:
            if slot.busy and wait_s > 0.0:
                self._idle.wait_for(lambda: not slot.busy or self._stopping, wait_s)
            if slot.busy or self._stopping:
                slot.skipped += 1
                return False
            slot.busy = True
        try:
            slot.time_s = self._capture.snapshot(sensor)
        except Exception as error:  # reported by the owner; the control loop goes on
            self.error = error
            with self._lock:
                slot.busy = False
            return False
        self._jobs.put(slot)
        return True

    def request_or_retry(
        self,
        sensor: str,
        lock: AbstractContextManager[object],
        *,
        wait_s: float = 0.0,
        gate: SnapshotGate | None = None,
    ) -> float | None:
        """A sensor's paced job: :meth:`request` a frame holding ``lock`` (the HAL's),
        once ``gate`` (when given) lets the live state be taken.

        Returns:
            The gate's delay, or :data:`RETRY_S` when the previous frame of ``sensor`` is
            still in flight (the pacer asks again that much later), else None (queued, or
            the renderer failed).
        """
        with lock:
            if gate is not None and (delay_s := gate()) > 0.0:
                return delay_s
            queued = self.request(sensor, wait_s=wait_s)
        return None if queued or self.error is not None else RETRY_S

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> bool:
        """Stop the thread after the frame it is rendering (idempotent).

        Returns:
            True when the thread has ended (or never started).
        """
        self._stopping = True
        if not self._thread.is_alive():
            return True
        self._jobs.put(None)
        self._thread.join(timeout_s)
        return not self._thread.is_alive()

    # -- render thread ---------------------------------------------------------------------

    def _run(self) -> None:
        name_os_thread(self._thread.name)
        try:
            with behind_ordinary_programs():  # the renderer's GL threads inherit the place
                developer = self._capture.open()
        except Exception as error:  # no GL context: the sensors stop, the robot does not
            self.error = error
            return
        finally:
            with _OPENED:
                _OPENING.discard(id(self))
                _OPENED.notify_all()
        try:
            while (slot := self._jobs.get()) is not None and not self._stopping:
                self._frame(developer, slot)
                if self.error is not None:
                    break
        finally:
            developer.close()

    def _frame(self, developer: FrameDeveloper[FrameT], slot: _Slot) -> None:
        """Develop ``slot``'s snapshot and publish it with the snapshot's time."""
        try:
            image = developer.develop(slot.sensor)
            self._publish(slot.sensor, image, slot.time_s)
            slot.rendered += 1
        except Exception as error:  # reported by the owner; the control loop goes on
            self.error = error
        finally:
            with self._lock:
                slot.busy = False
                self._idle.notify_all()
