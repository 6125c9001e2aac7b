"""ViewBridge: the deploy graph drawn in the browser view while it runs.

A pacer job sends the bodies' poses and the joints (:class:`~openral_hal.view_feed.ViewFeed`)
at ``rate_hz`` of wall time, holding the HAL's lock for the copy, so never during a control
tick; the command the joints hold (the HAL's hold action: the last action or trajectory
point applied) is the ``action`` plot. Camera frames come from the frames the graph renders
for ROS (:attr:`~openral_bridge.sim_sensor_bridge.SimSensorBridge.on_frame`), so the view
renders nothing of its own.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from openral_hal.view_feed import ViewFeed

from openral_bridge.pacer import PacedJob, Pacer

if TYPE_CHECKING:
    from openral_hal.protocol import RobotHal


class ViewBridge:
    """Feeds one browser view from one HAL on the node's pacer."""

    def __init__(
        self, hal: RobotHal, feed: ViewFeed, lock: threading.Lock, rate_hz: float = 30.0
    ) -> None:
        self.hal, self.feed, self.lock, self.rate_hz = hal, feed, lock, rate_hz
        self._job: PacedJob | None = None
        self._pacer: Pacer | None = None
        self._closed = False

    def start(self, pacer: Pacer) -> None:
        """Send the scene now, then every ``1 / rate_hz`` seconds."""
        self._pacer = pacer
        self._send()
        self._job = pacer.every(1.0 / self.rate_hz, self._send, "browser view")

    def frame(self, camera: str, image: npt.NDArray[np.uint8], time_s: float) -> None:
        """A frame the graph published (render or pacer thread)."""
        self.feed.frame(camera, image, time_s)

    def _send(self) -> None:
        with self.lock:
            hold = np.asarray(self.hal.hold_action(), dtype=np.float64).tolist()
            self.feed(dict(zip(self.hal.action_names, hold, strict=True)))

    def stop(self) -> None:
        """Stop sending and close the view's data stream (idempotent)."""
        if self._job is not None and self._pacer is not None:
            self._pacer.cancel(self._job)
        self._job = None
        if not self._closed:
            self._closed = True
            self.feed.view.close()
