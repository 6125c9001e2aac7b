"""A real robot as the control loop's plant: each cycle of its driver is one control tick.

A real HAL is never ticked: its driver's own loop keeps time, reading the robot, running a
hook, writing the command (:class:`~openral_hal.protocol.CycledHal`). The graph's
:class:`~openral_bridge.control_loop.ControlLoop` rides on that hook (:meth:`RealCadence.drive`):
every reading becomes a tick, so pending actions, joint trajectories, the trajectory action's
judgement and the state publishers work on a real robot exactly as on a simulated one, one
control period apart, with no second clock beating against the driver's. The tick runs on
a thread of its own, woken by the hook: the driver's cycle never waits for the graph (a
lock held elsewhere, a slow publisher); a tick still running when the next reading comes
takes that reading next (:attr:`RealCadence.coalesced` counts the readings skipped). A HAL
whose robot driver keeps time itself (:class:`~openral_hal.protocol.WritesAfterTick`) is
written by this thread after the tick, so an action reaches the robot in the cycle that took
it rather than the next.

What a tick means here: the action of the period (a pending one, or the trajectory's next
point) is handed to the HAL, whose envelope moves the goals towards it; nothing is stepped.
The state's time is its reading's system-clock time (a real robot's ROS time), and the
robot's model is posed at it (:class:`~openral_hal.protocol.TwinHal`) for ``/tf`` and
``/joint_states``. While the E-stop is latched the readings go on (the loop keeps publishing
them) and no action is passed on.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from openral_core.models import RobotDescription
from openral_hal.errors import HalError
from openral_hal.protocol import CycledHal, TwinHal, WritesAfterTick
from openral_hal.realtime import PRIORITY, answer_first
from openral_mujoco.state import FloatArray, JointStateSample

TICK_PRIORITY = PRIORITY - 1
"""The graph's tick runs just below the driver's own loop (see :mod:`openral_hal.realtime`)."""


class RealCadence:
    """A :class:`CycledHal` presented as the control loop's plant (see the module doc)."""

    is_real = True

    def __init__(self, hal: CycledHal) -> None:
        self.hal = hal
        self.coalesced = 0
        """Readings that came while a tick still ran (the next tick took the newest)."""
        self._reading = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._tick: Callable[[], None] | None = None

    def drive(self, tick: Callable[[], None] | None) -> None:
        """Run ``tick`` on a thread of its own after every reading of the HAL's loop (None:
        stop, once a tick in progress has ended)."""
        writes = isinstance(self.hal, WritesAfterTick)
        if tick is None:
            self.hal.on_cycle = None
            if writes:
                self.hal.writes_after_tick = False  # type: ignore[attr-defined]
            self._stop.set()
            self._reading.set()
            thread, self._thread = self._thread, None
            if thread is not None and thread is not threading.current_thread():
                thread.join(5.0)
            return
        self._tick = tick
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="real-control", daemon=True)
        self._thread.start()
        if writes:
            self.hal.writes_after_tick = True  # type: ignore[attr-defined]
        self.hal.on_cycle = self._read

    def _read(self) -> None:
        """The driver's hook: a new reading (never waits)."""
        if self._reading.is_set():
            self.coalesced += 1
        self._reading.set()

    def _run(self) -> None:
        answer_first(TICK_PRIORITY)  # it holds Python's lock the driver's loop waits for
        while True:
            self._reading.wait()
            self._reading.clear()
            if self._stop.is_set() or self._tick is None:
                return
            self._tick()
            if isinstance(self.hal, WritesAfterTick) and self.hal.writes_after_tick:
                self.hal.write_cycle()  # the tick's action in this cycle's command

    # -- the plant ---------------------------------------------------------------------------

    @property
    def control_period_s(self) -> float:
        """The driver's cycle [s]."""
        return self.hal.control_period_s

    def tick(self, action: object | None, *, glide: bool = False) -> bool:
        """Hand ``action`` to the HAL (unless the E-stop is latched); the robot's state
        moved on either way."""
        if action is not None and not self.hal.estopped:
            self.hal.send_action(action)
        return True

    def read_state(self) -> JointStateSample:
        """The newest reading, its time the system clock's [s]; the model posed at it."""
        sample = self.hal.read_state()
        if isinstance(self.hal, TwinHal):
            self.hal.pose_twin(sample)
        return sample._replace(sim_time_s=sample.stamp_ns / 1e9)

    def reset(self) -> str:
        """Refused: a real robot has no start to go back to.

        Raises:
            HalError: Always.
        """
        raise HalError(
            "a real robot cannot be reset: nothing puts its objects back; move it with an "
            "action or a joint trajectory"
        )

    # -- the rest of the HAL, as it is -------------------------------------------------------

    @property
    def description(self) -> RobotDescription:
        """The HAL's manifest."""
        return self.hal.description

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The HAL's joints."""
        return self.hal.joint_names

    @property
    def action_names(self) -> tuple[str, ...]:
        """The HAL's action slots."""
        return self.hal.action_names

    @property
    def connected(self) -> bool:
        """The HAL's."""
        return self.hal.connected

    def connect(self) -> None:
        """The HAL's."""
        self.hal.connect()

    def disconnect(self) -> None:
        """The HAL's."""
        self.hal.disconnect()

    def hold_action(self) -> FloatArray:
        """The measured pose as an action (never zeros)."""
        return self.hal.hold_action()

    def send_action(self, action: object) -> None:
        """The HAL's."""
        self.hal.send_action(action)

    @property
    def estopped(self) -> bool:
        """The HAL's E-stop."""
        return self.hal.estopped

    def estop(self) -> None:
        """The HAL's."""
        self.hal.estop()

    def release_estop(self) -> None:
        """The HAL's."""
        self.hal.release_estop()
