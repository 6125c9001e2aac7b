"""ViewFeed: what a MuJoCo-backed HAL shows in the browser view, one call per step.

Each call sends the bodies' poses of the HAL's live model (at most at the view's rate, in
simulated time), the manifest joints and the action on their plots, and every camera or
depth frame the HAL's last observation carries that was not sent before. It reads the HAL
only, so the same feed serves ``sim run``, ``sim replay`` and the deploy graph (which also
hands it the frames it renders for ROS, :meth:`frame`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from openral_hal.protocol import MujocoBacked, ObservingHal, RobotHal

if TYPE_CHECKING:  # rerun-sdk, an optional extra, is imported by whoever opens the view
    from openral_sim.browser_view import BrowserView


class ViewFeed:
    """Feeds one :class:`~openral_sim.browser_view.BrowserView` from one HAL."""

    def __init__(self, view: BrowserView, hal: RobotHal) -> None:
        """Args:
        view: The view to draw in (its model must be the HAL's).
        hal: A connected HAL backed by MuJoCo.
        """
        self.view, self.hal = view, hal
        self._sent: dict[str, npt.NDArray[np.generic]] = {}

    def __call__(self, action: Mapping[str, float] | None = None) -> None:
        """Send the HAL's state now, and ``action`` (the one just applied, by slot name:
        joint slots, or an env's end-effector slots) when given."""
        handles = self.hal.mujoco_handles() if isinstance(self.hal, MujocoBacked) else None
        state = self.hal.read_state()
        time_s = float(state.sim_time_s or 0.0)
        posed = handles is not None and self.view.pose(handles[1], time_s)
        if posed:
            self.view.plot(
                "joints", dict(zip(state.names, state.positions.tolist(), strict=True)), time_s
            )
            if action is not None:
                self.view.plot("action", action, time_s)
        if isinstance(self.hal, ObservingHal):
            obs = self.hal.last_observation()
            for name, image in obs.images.items():
                if self._new(name, image):
                    self.view.image(name, image, time_s)
            for name, frame in obs.depth.items():
                if self._new(f"{name}/depth", frame.depth_m):
                    self.view.depth(name, frame.depth_m, time_s)

    def frame(self, camera: str, image: npt.NDArray[np.uint8], time_s: float) -> None:
        """A camera frame rendered elsewhere (the deploy graph's render thread)."""
        self.view.image(camera, image, time_s)

    def _new(self, name: str, array: npt.NDArray[np.generic]) -> bool:
        """True the first time this exact array is seen for ``name`` (observations keep
        handing out the last frame until a new one is due); the last one is kept, so its
        identity cannot pass to a new array."""
        if self._sent.get(name) is array:
            return False
        self._sent[name] = array
        return True
