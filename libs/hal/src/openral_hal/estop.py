"""The E-stop: its latch and every effect it has on a HAL, written once.

Latching (:meth:`EStopLatch.estop`):

- every later action, tick and base command is refused with
  :class:`~openral_hal.errors.EStopLatched` (:meth:`EStopLatch._refuse_when_estopped`),
  and a refused command changes nothing;
- a simulated scene does not advance: :meth:`Tickable.tick
  <openral_hal.protocol.Tickable.tick>` returns False and time is frozen (the control loop
  then aborts a trajectory in flight, as ``/openral/estop`` does at once);
- a mobile base halts at once (the HAL's :meth:`EStopLatch._on_latch`).

Releasing (:meth:`EStopLatch.release_estop`) first makes the pose the E-stop froze the
targets (:meth:`EStopLatch._on_release`), so nothing jumps, then unlatches. A reset keeps
the latch as it is.
"""

from __future__ import annotations

from openral_hal.errors import EStopLatched


class EStopLatch:
    """The E-stop latch, written once for every HAL (a mixin).

    A HAL calls :meth:`_refuse_when_estopped` before applying an action and overrides
    :meth:`_on_release` to re-aim its targets at the current pose so nothing jumps.
    """

    _estopped: bool = False

    @property
    def estopped(self) -> bool:
        """True while the E-stop is latched."""
        return self._estopped

    def estop(self) -> None:
        """Latch the E-stop: actions are refused and the robot is held (see the module)."""
        self._estopped = True
        self._on_latch()

    def release_estop(self) -> None:
        """Unlatch the E-stop; the HAL's targets are the current pose, so nothing jumps."""
        self._on_release()
        self._estopped = False

    def _on_latch(self) -> None:
        """Hook run after latching (default: nothing; a mobile base halts)."""

    def _on_release(self) -> None:
        """Hook run before unlatching (default: nothing)."""

    def _refuse_when_estopped(self) -> None:
        """Raise EStopLatched while latched."""
        if self._estopped:
            raise EStopLatched()
