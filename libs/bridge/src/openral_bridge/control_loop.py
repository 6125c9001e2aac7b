"""The control loop of a simulated robot under ``deploy sim``: one writer steps the scene.

A real arm's controller runs at its own rate whatever its clients do; this loop gives a
simulated one the same behaviour. A job on the node's :class:`~openral_bridge.pacer.Pacer`
runs once per state period: a control period (:attr:`Tickable.control_period_s`, the
scene's ``control_freq_hz``) stepped in :attr:`StateParted.state_parts
<openral_hal.protocol.StateParted.state_parts>` equal parts (its ``state_rate_hz``), so the
state is new at every tick. The first tick of a period starts it:

- with the newest action offered since (:meth:`ControlLoop.offer`, any thread); one replaced
  before a tick, or dropped (by :meth:`stop`, or the E-stop), is counted in
  :attr:`superseded`, never applied and never silently lost;
- else, while a joint trajectory runs (:attr:`ControlLoop.follower`), gliding to its point
  at the period's end; an offered action pre-empts it, and a tick the E-stop keeps from
  stepping aborts it;
- else, with an end-effector target (:attr:`ControlLoop.ee`), gliding to the IK's step
  towards it; an action, a trajectory, the E-stop and a reset end the target;
- else holding what is commanded (:meth:`Tickable.tick` with None).

The other ticks of a period step on with what it started with: an action offered meanwhile
waits for the next period (actions keep the control rate).

A reset (:meth:`ControlLoop.reset`, any thread) is carried out by the next tick instead of
a step: the scene is reset, stepped once with its hold and ``on_reset`` runs on the loop's
thread before any other periodic job, so sensors can publish the start state again.

Malformed actions are refused where they arrive (the node validates them). While the E-stop
is latched the HAL does not advance (time freezes too). A late tick is not made up: the loop
never runs faster than real time, and says so once per slow spell with the measured
real-time factor (:class:`~openral_bridge.real_time.RealTimeWatch`).

Threads: a tick steps the HAL holding ``lock``, the lock every other user of the HAL takes,
so nothing reads or changes the scene mid-step. :meth:`offer` never waits for a tick.

A real robot is driven, not ticked: its driver's loop calls :meth:`ControlLoop.tick` after
each reading (:meth:`ControlLoop.start_driven`, through
:class:`~openral_bridge.real_cadence.RealCadence`). While its E-stop is latched each tick
still reads it (and runs the readers and watchers), applies nothing and aborts a trajectory.

This replaces the design record's idle stepper, which stepped only while nobody commanded
the scene and at the camera rate (so simulated time ran at the camera rate's pace).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from openral_hal.protocol import StateParted, Tickable
from openral_mujoco.state import FloatArray, JointStateSample

from openral_bridge.loop_terms import RESET_TIMEOUT_S, Drive, Following, ResetFailed, ResetRequest
from openral_bridge.pacer import PacedJob, Pacer
from openral_bridge.real_time import RealTimeWatch
from openral_bridge.trajectory_follower import DesiredPoint, TrajectoryFollower

if TYPE_CHECKING:
    from rclpy.node import Node

__all__ = ["ControlLoop", "Drive", "Following", "ResetFailed"]

WARN_EVERY_S = 2.0
"""At most one warning per this many seconds for a stream of failing ticks [s]."""


class ControlLoop:
    """Steps one :class:`Tickable` HAL once per state period on a :class:`Pacer`."""

    def __init__(
        self,
        node: Node,
        hal: Tickable,
        on_tick: Callable[[float | None], None] | None = None,
        *,
        lock: threading.Lock | None = None,
        follower: TrajectoryFollower | None = None,
        on_sample: Callable[[DesiredPoint], None] | None = None,
        on_reset: Callable[[], None] | None = None,
    ) -> None:
        """Nothing runs until :meth:`start`.

        Args:
            node: The node whose logger reports.
            hal: A connected simulated HAL.
            on_tick: Called after every tick that stepped with its simulated time [s]
                (None for a HAL without one), e.g. to publish ``/clock``.
            lock: The HAL's lock, held while a tick steps and reads it (default: own).
            follower: The joint trajectories to follow (None: none).
            on_sample: Called with the desired point of each period that followed one.
            on_reset: Called on the loop's thread right after a reset's tick (the HAL lock
                is not held during these three).
        """
        self.node, self.hal, self.on_tick = node, hal, on_tick
        self.lock = lock if lock is not None else threading.Lock()
        self.period_s = float(hal.control_period_s)
        """The control period: actions, trajectory samples and ee steps at its start [s]."""
        parted = hal if isinstance(hal, StateParted) else None
        self.parts, self._step = (parted.state_parts, parted.tick_part) if parted else (1, hal.tick)
        self.tick_period_s = self.period_s / self.parts
        """Simulated time one tick advances: the state period [s]."""
        self._phase = 0  # ticks of the current control period stepped, modulo parts
        self.ticks = self.applied = self.superseded = self.failed = 0
        """Ticks that stepped; actions applied; superseded (see above); ticks that raised."""
        self.watch = RealTimeWatch()
        self.state: JointStateSample | None = None
        """The HAL's state after the last tick that stepped (None: none yet, or it failed)."""
        self.follower, self.on_sample, self.on_reset = follower, on_sample, on_reset
        self.followed = 0
        """Ticks that glided along a trajectory or towards an end-effector target."""
        self.ee: Following | None = None
        """The end-effector target (:mod:`openral_bridge.ee_bridge`), to :attr:`on_ee_sample`."""
        self.on_ee_sample: Callable[[DesiredPoint], None] | None = None
        self.watchers: list[Callable[[JointStateSample], None]] = []
        """Called with the state after every tick that stepped (the HAL lock not held)."""
        self.reporters: list[Callable[[], None]] = []
        """Called after every tick that did not fail, also E-stopped (the state publishers)."""
        self.readers: list[Callable[[], None]] = []
        """Called in order, holding the HAL lock, right after every tick that stepped the scene
        (and a reset's tick): each copies what it publishes from the live scene, so nothing
        reads the scene in the middle of a step and the copies all show the same state."""
        self._pending: FloatArray | None = None
        self._slots: dict[int, float] = {}  # command_slots' values for the next period
        self._reset: ResetRequest | None = None
        self._pending_lock = threading.Lock()
        self._job: tuple[Pacer, PacedJob] | None = None
        self._driven: Drive | None = None

    @property
    def ticks_left(self) -> int:
        """Ticks still to step in this control period (0 right after the one that ended it)."""
        return (self.parts - self._phase) % self.parts

    @property
    def running(self) -> bool:
        """True between :meth:`start` (or :meth:`start_driven`) and :meth:`stop`."""
        return self._job is not None or self._driven is not None

    def start(self, pacer: Pacer) -> None:
        """Tick once now (so simulated time has advanced before anything is published),
        then once per state period on ``pacer``."""
        self.stop()
        self.watch.restart()
        self.tick()
        self._job = (pacer, pacer.every(self.tick_period_s, self.tick, "control"))

    def start_driven(self, drive: Drive) -> None:
        """Tick once now, then whenever the robot's driver calls back (``drive(tick)``;
        ``drive(None)`` at :meth:`stop` takes it back)."""
        self.stop()
        self.watch.restart()
        self.tick()
        self._driven = drive
        drive(self.tick)

    def stop(self) -> None:
        """Unschedule the tick (idempotent; returns once a tick in progress has ended); a
        pending action is dropped and counted."""
        if self._job is not None:
            pacer, job = self._job
            self._job = None
            pacer.cancel(job)
        if self._driven is not None:
            drive, self._driven = self._driven, None
            drive(None)
        with self._pending_lock:
            self._drop_pending()
            reset, self._reset = self._reset, None
        if reset is not None:
            reset.error = "the control loop stopped before the reset"
            reset.done.set()
        for following in (self.follower, self.ee):
            if following is not None:
                following.cancel("the control loop stopped")

    def add_reader(self, read: Callable[[], None]) -> None:
        """Run ``read`` after every tick that steps (see :attr:`readers`), and once now,
        holding the HAL lock, when a tick already stepped (so it has a state at once)."""
        self.readers.append(read)
        if self.state is not None:
            with self.lock:
                read()

    def offer(self, action: FloatArray) -> bool:
        """Make ``action`` (validated) the next period's (any thread); it pre-empts a joint
        trajectory. True when it ended one."""
        follower = self.follower
        preempted = follower.cancel("a safe_action pre-empted it") if follower else False
        if self.ee is not None:
            self.ee.cancel("a safe_action pre-empted it")
        with self._pending_lock:
            if self._pending is not None:
                self.superseded += 1
            self._pending = action
        return preempted

    def reset(self, timeout_s: float = RESET_TIMEOUT_S) -> str:
        """Have the next tick reset the scene (see the module doc) and wait for it; a pending
        action and any trajectory are dropped. Returns the HAL's account of the reset.

        Raises:
            ResetFailed: The loop is not running, the tick did not come within
                ``timeout_s``, or the HAL's reset raised (the message says which).
        """
        if not self.running:
            raise ResetFailed("the control loop is not running")
        request = ResetRequest()
        with self._pending_lock:
            self._drop_pending()
            self._reset = request
        if not request.done.wait(timeout_s):
            with self._pending_lock:
                withdrawn = self._reset is request
                if withdrawn:  # no later tick carries out a reset its caller gave up on
                    self._reset = None
            if withdrawn or not request.done.wait(timeout_s):
                raise ResetFailed(f"no control tick carried the reset out within {timeout_s:g} s")
        if request.error is not None:
            raise ResetFailed(request.error)
        return request.text

    def tick(self) -> None:
        """Advance the scene one control period (see the module doc); a HAL error is
        counted and logged, never raised (``on_tick``'s own errors are)."""
        starts = self._phase == 0  # a control period starts: actions and samples are taken
        with self._pending_lock:
            action = None
            if starts:
                action, self._pending = self._pending, None
            reset, self._reset = self._reset, None
        if reset is not None:
            self._carry_out(reset)
            return
        sample: DesiredPoint | None = None
        toward_ee = False
        try:
            with self.lock:
                held = self.hal.estopped  # a real robot still reads on; it takes nothing
                dropped = action if held else None
                if held:
                    action = None
                elif starts:
                    action, sample, toward_ee = self._period_action(action)
                stepped = self._step(action, glide=sample is not None)
                if stepped:
                    self._phase = (self._phase + 1) % self.parts
                state = self.hal.read_state() if stepped else self.state
                self.state = state
                if stepped:
                    self._read()
        except Exception as error:  # a diverged scene, or a bug: never the end of the graph
            self.state = None
            self._abort_trajectory(f"the control tick failed ({type(error).__name__})")
            self._failed(error)
            return
        if not stepped or held:  # E-stopped: nothing applied (a scene's time is frozen too)
            self.watch.restart()
            frozen = "" if stepped else ": the scene did not step"
            self._abort_trajectory(f"the E-stop is latched{frozen}")
            if (dropped if held else action) is not None and sample is None:
                with self._pending_lock:
                    self.superseded += 1
            if not stepped:
                self._report()  # a frozen scene's state is still published
                return
        self._after_step(state, action is not None and sample is None, sample, toward_ee)
        self._report()

    def _report(self) -> None:
        for report in self.reporters:
            report()

    def command_slots(self, values: dict[int, float]) -> None:
        """Have the next period set these action slots (index → value, already validated)
        on top of whatever it applies: an offered action, a trajectory's sample or the hold
        (any thread; e.g. a gripper command that must not end the arm's trajectory)."""
        with self._pending_lock:
            self._slots.update(values)

    def _period_action(
        self, offered: FloatArray | None
    ) -> tuple[FloatArray | None, DesiredPoint | None, bool]:
        """The action starting a period: ``offered``, else what :meth:`_follow_step` gives,
        with the slots of :meth:`command_slots` set on top (under the HAL lock)."""
        action, sample, toward_ee = (
            (offered, None, False) if offered is not None else self._follow_step()
        )
        with self._pending_lock:
            slots, self._slots = self._slots, {}
        if slots:
            hold = self.hal.hold_action() if action is None else action
            action = np.array(hold, dtype=np.float64)
            for index, value in slots.items():
                action[index] = value
        return action, sample, toward_ee

    def _follow_step(self) -> tuple[FloatArray | None, DesiredPoint | None, bool]:
        """(action, desired point, towards the ee target) of this tick: a running trajectory
        first (it ends an ee target), else the ee target, else (None, None, False); under
        the HAL lock."""
        now_s = self.state.sim_time_s if self.state is not None else None
        if now_s is None or (self.follower is None and self.ee is None):
            return None, None, False
        hold = np.asarray(self.hal.hold_action(), dtype=np.float64)
        if self.follower is not None:
            step = self.follower.next_action(hold, now_s, self.period_s)
            if step is not None:
                if self.ee is not None:
                    self.ee.cancel("a joint trajectory pre-empted it")
                return step[0], step[1], False
        if self.ee is not None and (step := self.ee.next_action(hold, now_s, self.period_s)):
            return step[0], step[1], True
        return None, None, False

    def _after_step(
        self, state: JointStateSample | None, applied: bool, sample: DesiredPoint | None, ee: bool
    ) -> None:
        self.ticks += 1
        self.applied += int(applied)
        sim_time = state.sim_time_s if state is not None else None
        if self.on_tick is not None:
            self.on_tick(sim_time)
        if sample is not None:
            self.followed += 1
            publish = self.on_ee_sample if ee else self.on_sample
            if publish is not None:
                publish(sample)
        if state is not None:
            for watch in self.watchers:
                watch(state)
        if sim_time is not None:
            self._check_pace(sim_time)

    def _carry_out(self, request: ResetRequest) -> None:
        """Reset, step once with the hold, tell ``on_tick`` and ``on_reset``; the outcome
        goes to ``request``."""
        try:
            with self.lock:
                if self.follower is not None:  # the old path never runs from the reset pose
                    self.follower.cancel("the scene was reset")
                if self.ee is not None:
                    self.ee.cancel("the scene was reset")
                request.text = self.hal.reset()
                stepped = self._step(None)
                self._phase = 1 % self.parts if stepped else 0  # it started a period
                self.state = self.hal.read_state() if stepped else None
                if stepped:
                    self._read()
        except Exception as error:  # reported to the caller, never the end of the graph
            request.error = f"the reset failed ({type(error).__name__}: {error})"
            request.done.set()
            return
        self.watch.restart()
        try:
            if self.on_tick is not None and self.state is not None:
                self.on_tick(self.state.sim_time_s)
            if self.on_reset is not None:
                self.on_reset()
        finally:
            request.done.set()

    def _read(self) -> None:
        """Run the readers (holding the HAL lock)."""
        for read in self.readers:
            read()

    def _drop_pending(self) -> None:
        """Drop a waiting action, counted as superseded (holding ``_pending_lock``)."""
        if self._pending is not None:
            self.superseded += 1
            self._pending = None

    def _abort_trajectory(self, reason: str) -> None:
        if self.ee is not None and self.ee.cancel(reason):
            self._log().warning(f"end-effector target dropped: {reason}")
        if self.follower is not None and self.follower.cancel(reason):
            self._log().warning(f"joint trajectory aborted: {reason}")

    def _check_pace(self, sim_time: float) -> None:
        factor = self.watch.update(time.monotonic(), sim_time)
        if factor is not None:
            self._log().warning(
                f"the simulation runs at {factor:.2f}x real time over the last "
                f"{self.watch.window_s:g} s: this machine cannot keep up with the "
                f"{1.0 / self.tick_period_s:g} Hz control loop"
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
