"""The terms a control loop is driven by: what it follows, how a driver drives it, and
how a reset is handed to its thread (:mod:`openral_bridge.control_loop`)."""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from openral_mujoco.state import FloatArray

from openral_bridge.trajectory_follower import DesiredPoint

RESET_TIMEOUT_S = 10.0
"""Longest wait of :meth:`ControlLoop.reset` for a tick to carry the reset out [s]."""


class Following(Protocol):
    """What a control loop follows between offered actions: a path, a target."""

    def next_action(
        self, hold: FloatArray, now_s: float, period_s: float
    ) -> tuple[FloatArray, DesiredPoint] | None:
        """The action of the coming period and its desired point (None: nothing to follow)."""
        ...

    def cancel(self, reason: str = "cancelled") -> bool:
        """Stop following; True when something was followed."""
        ...


Drive = Callable[[Callable[[], None] | None], None]
"""Hands a driver the tick to call after each of its readings (None: takes it back)."""


class ResetFailed(RuntimeError):
    """A reset was not carried out (the loop stopped, timed out, or the HAL raised)."""


@dataclass
class ResetRequest:
    """One reset handed to the loop's thread, and its outcome."""

    done: threading.Event = field(default_factory=threading.Event)
    text: str = ""
    error: str | None = None
