"""The real driver's own loop: read every motor, let the graph act, write every goal.

Once per control period, on a thread of its own (as ros2_control's read, update, write):

1. one Sync Read of every motor's present block; it becomes the newest sample;
2. ``on_cycle`` runs (the graph's control step: it may aim the envelope at a new command);
3. one Sync Write of every goal, one envelope step closer to the command
   (:class:`~openral_real.motion_envelope.MotionEnvelope`).

Failures latch the E-stop (:class:`CycleLatch`) with one line naming the motor and the
fault, and nothing is written after it but the E-stop's own effect: a motor that does not
answer or answers corrupt twice (a checksum storm), a fault bit in a reply (overload,
over-temperature, voltage), the port failing (unplugged), and a reading older than two
control periods (the loop fell behind). A latch from a fault is noticed by the read that
meets it, within two periods of the fault. The E-stop's effect (``estop``: ``hold`` writes
the measured positions as goals, ``torque_off`` turns torque off) is applied by the next
cycle, which :meth:`BusCycle.wake` starts at once. A write already past its check of the
latch finishes before ``estop()`` returns (:meth:`BusCycle.settle_latch`): once it has
returned, no goal but the effect reaches the bus.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from openral_core.servo_models import fault_text
from openral_hal.realtime import answer_first
from openral_mujoco.state import JointStateSample

from openral_real.errors import BusFault
from openral_real.feetech_bus import FeetechBus, ServoReading
from openral_real.motion_envelope import MotionEnvelope
from openral_real.servo_units import ServoUnits

STATS_KEPT = 100_000
"""Cycles whose timing is kept for the benchmark (about 17 minutes at 100 Hz)."""


class CycleLatch(Protocol):
    """What the loop needs of the E-stop it serves."""

    @property
    def estopped(self) -> bool:
        """True while latched."""
        ...

    def latch_fault(self, reason: str) -> None:
        """Latch the E-stop because of a fault (once; the reason is said in one line)."""
        ...


@dataclass
class CycleTimes:
    """When the cycles ran: start lateness and bus round trips [s]."""

    late_s: deque[float] = field(default_factory=lambda: deque(maxlen=STATS_KEPT))
    """How long after its due time each cycle started."""
    round_trip_s: deque[float] = field(default_factory=lambda: deque(maxlen=STATS_KEPT))
    """Sync Read plus Sync Write of each cycle (without ``on_cycle``)."""
    cycles: int = 0


class BusCycle:
    """Reads, acts and writes once per control period (see the module doc)."""

    def __init__(
        self,
        bus: FeetechBus,
        units: ServoUnits,
        envelope: MotionEnvelope,
        latch: CycleLatch,
        period_s: float,
        estop_torque_off: bool,
    ) -> None:
        """Nothing runs until :meth:`start`."""
        self.bus, self.units, self.envelope, self.latch = bus, units, envelope, latch
        self.period_s, self.estop_torque_off = period_s, estop_torque_off
        self.on_cycle: Callable[[], None] | None = None
        """Run after each read, before the write (the graph's control step)."""
        self.times = CycleTimes()
        self.hook_failures = 0
        """``on_cycle`` calls that raised (each said, throttled, by the owner's log)."""
        self.last_hook_error: str | None = None
        self.effect_pending = False
        """The E-stop's effect is still to be written (set by the owner when it latches)."""
        self.torque_on_pending = False
        """Torque is to be turned on again at the measured positions (after a release)."""
        self.realtime = False
        """True when the loop's thread got real-time scheduling (see :func:`answer_first`)."""
        self._lock = threading.Lock()
        self._write_gate = threading.Lock()
        self._readings: list[ServoReading] | None = None
        self._sample: JointStateSample | None = None
        self._last_ok = 0.0
        self._started = False
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None

    # -- what it read ------------------------------------------------------------------------

    def latest(self) -> tuple[list[ServoReading], JointStateSample, float]:
        """The newest present block, its sample and its age [s] (0 until the loop first
        starts: the servos hold the goals written at the seed's reading until then).

        Raises:
            RuntimeError: Nothing was read yet.
        """
        with self._lock:
            readings, sample, read_at = self._readings, self._sample, self._last_ok
        if readings is None or sample is None:
            raise RuntimeError("the bus has not been read yet")
        return readings, sample, time.monotonic() - read_at if self._started else 0.0

    def seed(self, readings: list[ServoReading]) -> None:
        """The present block read at connect (the first sample)."""
        self._store(readings)

    # -- the thread --------------------------------------------------------------------------

    def start(self) -> None:
        """Cycle on a thread of its own until :meth:`stop`."""
        if not self._started:  # the seed stood for the arm until now: nothing moved it
            self._started = True
            with self._lock:
                self._last_ok = time.monotonic()
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="feetech-bus", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop cycling and join the thread (idempotent)."""
        self._stop.set()
        self._wake.set()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(5.0)

    @property
    def running(self) -> bool:
        """True while the thread cycles."""
        return self._thread is not None and self._thread.is_alive()

    def settle_latch(self) -> None:
        """Return once no write that began before the latch is still under way: a caller
        that latched and then calls this knows the next goal on the bus is the effect."""
        with self._write_gate:
            pass

    def wake(self) -> None:
        """Run the next cycle now (an E-stop's effect waits for no period)."""
        self._wake.set()

    def _run(self) -> None:
        self.realtime = answer_first()  # granted to root or CAP_SYS_NICE, else as it is
        due = time.monotonic() + self.period_s
        while not self._stop.is_set():
            self._wake.wait(max(0.0, due - time.monotonic()))
            self._wake.clear()
            if self._stop.is_set():
                return
            started = time.monotonic()
            self.times.late_s.append(max(0.0, started - due))
            try:
                self.cycle()
            except Exception as error:  # a bug of the driver: stop the arm, keep the thread
                self._fault(f"the bus loop failed ({type(error).__name__}: {error})")
            due = max(due + self.period_s, started)  # late: no catching up in bursts

    def cycle(self) -> None:
        """One read, act, write (see the module doc); never raises."""
        if self._last_ok and time.monotonic() - self._last_ok > 2 * self.period_s:
            age_ms = (time.monotonic() - self._last_ok) * 1000
            self._fault(
                f"the last reading of the bus is {age_ms:.0f} ms old (control period "
                f"{self.period_s * 1000:g} ms): the driver fell behind"
            )
        began = time.monotonic()
        try:
            readings = self.bus.read_present()
        except BusFault as error:
            self._fault(str(error))
            return
        read_s = time.monotonic() - began
        self._store(readings)
        self._check_faults(readings)
        self._act()
        began = time.monotonic()
        try:
            self._write(readings)
        except BusFault as error:
            self._fault(str(error))
        self.times.round_trip_s.append(read_s + time.monotonic() - began)
        self.times.cycles += 1

    # -- internals ---------------------------------------------------------------------------

    def _store(self, readings: list[ServoReading]) -> None:
        sample = self.units.sample(readings, time.time_ns())
        with self._lock:
            self._readings, self._sample, self._last_ok = readings, sample, time.monotonic()

    def _check_faults(self, readings: list[ServoReading]) -> None:
        for servo_id, reading in zip(self.bus.ids, readings, strict=True):
            if reading.faults:
                self._fault(f"{self.bus.names[servo_id]} reports {fault_text(reading.faults)}")
                return

    def _act(self) -> None:
        hook = self.on_cycle
        if hook is None:
            return
        try:
            hook()
        except Exception as error:  # the graph's bug: said by the owner, never the bus's end
            self.hook_failures += 1
            self.last_hook_error = f"{type(error).__name__}: {error}"

    def _write(self, readings: list[ServoReading]) -> None:
        with self._write_gate:  # the latch is read and the goals written as one step
            self._write_unless_latched(readings)

    def _write_unless_latched(self, readings: list[ServoReading]) -> None:
        if self.latch.estopped:
            if self.effect_pending:
                self.effect_pending = False
                self._estop_effect(readings)
            return
        if self.torque_on_pending:
            self.bus.write_goals([r.position for r in readings])
            self.bus.write_all("Torque_Enable", [1] * len(readings))
            self.torque_on_pending = False
        self.bus.write_goals(self.units.steps(self.envelope.step()))

    def _estop_effect(self, readings: list[ServoReading]) -> None:
        if self.estop_torque_off:
            self.bus.write_all("Torque_Enable", [0] * len(readings))
        else:
            self.bus.write_goals([r.position for r in readings])

    def _fault(self, reason: str) -> None:
        if self.latch.estopped:
            return
        self.effect_pending = False  # a fault writes no goal: the servos keep their last one
        self.latch.latch_fault(reason)
        if self.estop_torque_off:
            with contextlib.suppress(BusFault):  # a bus that is gone cannot be told more
                self.bus.write_all("Torque_Enable", [0] * len(self.bus.ids))
