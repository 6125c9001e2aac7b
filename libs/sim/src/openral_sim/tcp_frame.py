"""Where the robot's tool centre point (``sim.tcp``) is in a scene's model, and its world
position in that model's data."""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core.tcp_wiring import TcpWiring
from openral_mujoco.errors import HalError
from openral_mujoco.state import FloatArray


class TcpFrame:
    """The body or site the TCP is fixed to, and the TCP's offset in it."""

    def __init__(self, kind: str, frame: int, offset: FloatArray) -> None:
        self.kind, self.frame, self.offset = kind, frame, offset

    @classmethod
    def locate(cls, model: mujoco.MjModel, tcp: TcpWiring) -> TcpFrame:
        """``tcp`` found in ``model``.

        Raises:
            HalError: The model has no such body or site.
        """
        kind = mujoco.mjtObj.mjOBJ_SITE if tcp.kind == "site" else mujoco.mjtObj.mjOBJ_BODY
        frame = mujoco.mj_name2id(model, kind, tcp.frame)
        if frame < 0:
            raise HalError(f"the scene's model has no {tcp.kind} {tcp.frame!r} (sim.tcp)")
        return cls(tcp.kind, frame, np.asarray(tcp.offset_m, dtype=np.float64))

    def position(self, data: mujoco.MjData) -> FloatArray:
        """The TCP's world position [m]."""
        site = self.kind == "site"
        origin: FloatArray = (data.site_xpos if site else data.xpos)[self.frame]
        axes: FloatArray = (data.site_xmat if site else data.xmat)[self.frame].reshape(3, 3)
        return origin + axes @ self.offset
