"""The control loop of a simulated robot under ``deploy sim``: one writer steps the scene.

A real arm's controller runs at its own rate whatever its clients do; this loop gives a
simulated one the same behaviour. A wall-clock timer on the node fires once per control
period (:attr:`Tickable.control_period_s`, the scene's ``control_freq_hz``) and each tick
advances the scene by exactly one period:

- with the newest action that arrived since the last tick (:meth:`ControlLoop.offer`); an
  action replaced by a newer one before a tick is counted in :attr:`superseded`, never
  applied and never silently lost;
- with no new action, holding what is commanded (:meth:`Tickable.tick` with None: the targets
  in force on a position-controlled scene, the backend's hold on a delta controller).

Malformed actions are refused where they arrive (the node validates them), so they never
reach, delay or stop the loop. While the E-stop is latched the HAL does not advance (time
freezes too). A tick that is late is not made up: the loop never runs faster than real
time, and when the machine cannot keep up it says so once per slow spell with the measured
real-time factor (:class:`~openral_bridge.real_time.RealTimeWatch`).

This replaces the design record's idle stepper, which stepped only while nobody commanded
the scene and at the camera rate (so simulated time ran at the camera rate's pace). The
loop runs on the node's single-threaded executor, so it never runs at the same time as the
node's other callbacks.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from openral_hal.protocol import Tickable
from openral_mujoco.state import FloatArray

from openral_bridge.real_time import RealTimeWatch

if TYPE_CHECKING:
    from rclpy.node import Node

WARN_EVERY_S = 2.0
"""At most one warning per this many seconds for a stream of failing ticks [s]."""


class ControlLoop:
    """Steps one :class:`Tickable` HAL once per control period on a node's timer."""

    def __init__(
        self, node: Node, hal: Tickable, on_tick: Callable[[float | None], None] | None = None
    ) -> None:
        """Nothing runs until :meth:`start`.

        Args:
            node: The node that owns the timer (and whose logger reports).
            hal: A connected simulated HAL.
            on_tick: Called after every tick that advanced the scene with its simulated
                time [s] (None for a HAL without one), e.g. to publish ``/clock``.
        """
        self.node = node
        self.hal = hal
        self.on_tick = on_tick
        self.period_s = float(hal.control_period_s)
        self.ticks = 0
        """Ticks that advanced the scene."""
        self.applied = 0
        """Actions applied by a tick."""
        self.superseded = 0
        """Actions replaced by a newer one before any tick applied them."""
        self.failed = 0
        """Ticks that raised (a diverged simulation, a refused action)."""
        self.watch = RealTimeWatch()
        self._pending: FloatArray | None = None
        self._timer: Any = None

    @property
    def running(self) -> bool:
        """True between :meth:`start` and :meth:`stop`."""
        return self._timer is not None

    def start(self) -> None:
        """Tick once now (so simulated time has advanced before anything is published),
        then once per control period."""
        self.stop()
        self.watch.restart()
        self.tick()
        self._timer = self.node.create_timer(self.period_s, self.tick)

    def stop(self) -> None:
        """Destroy the timer (idempotent); a pending action is dropped and counted."""
        if self._timer is not None:
            self.node.destroy_timer(self._timer)
            self._timer = None
        if self._pending is not None:
            self.superseded += 1
            self._pending = None

    def offer(self, action: FloatArray) -> None:
        """Make ``action`` (already validated) the one the next tick applies."""
        if self._pending is not None:
            self.superseded += 1
        self._pending = action

    def tick(self) -> None:
        """Advance the scene one control period (see the module doc); never raises."""
        action, self._pending = self._pending, None
        try:
            stepped = self.hal.tick(action)
        except Exception as error:  # a diverged scene, or a bug: never the end of the graph
            self._failed(error)
            return
        if not stepped:  # E-stopped: time is frozen on purpose
            self.watch.restart()
            return
        self.ticks += 1
        self.applied += int(action is not None)
        sim_time = self.hal.read_state().sim_time_s
        if self.on_tick is not None:
            self.on_tick(sim_time)
        if sim_time is not None:
            self._check_pace(sim_time)

    def _check_pace(self, sim_time: float) -> None:
        factor = self.watch.update(time.monotonic(), sim_time)
        if factor is not None:
            self._log().warning(
                f"the simulation runs at {factor:.2f}x real time over the last "
                f"{self.watch.window_s:g} s: this machine cannot keep up with the "
                f"{1.0 / self.period_s:g} Hz control loop"
            )

    def _failed(self, error: Exception) -> None:
        self.failed += 1
        self.watch.restart()
        name = type(error).__name__
        self._log().error(
            f"control tick failed ({name}: {error})", throttle_duration_sec=WARN_EVERY_S
        )

    def _log(self) -> Any:
        """The node's logger (rclpy's logger is untyped)."""
        return self.node.get_logger()  # type: ignore[no-untyped-call]
