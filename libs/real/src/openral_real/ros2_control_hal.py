"""Ros2ControlHal: an arm with a ros2_control driver (franka_ros2, ur_robot_driver, ...) as a
real RobotHal, through :class:`~openral_real.ros2_control_link.Ros2ControlLink`.

The robot driver keeps time: each of its joint states is one cycle of this HAL (read, run
:attr:`on_cycle`, write), as a Feetech bus read is one cycle of the Feetech driver. The
safety rules are the real path's:

- never ticked, never attached to a scene; connecting waits for a reading of every manifest
  joint and for the driver's controllers, and sends nothing before;
- the goal starts at the measured pose and moves towards the command within the manifest's
  position and velocity limits, slowly at first
  (:class:`~openral_real.motion_envelope.MotionEnvelope`); each cycle sends the goal as a
  one-point trajectory reached one control period later, or later still when the arm lags
  so far behind that the velocity limits need longer; hold is the measured pose, and an
  all-zero action is refused unless the manifest allows it;
- the E-stop latches on request and when the readings stop or their stamps stop advancing
  for two control periods (one line says which); its effect is one hold trajectory at the
  measured pose and the gripper's goal cancelled; nothing is sent after it until release,
  which starts again from the measured pose;
- disconnecting sends a hold at the measured pose, then closes the link.

A gripper with a ``gripper_action`` takes GripperCommand goals in the driver's units (the
joint's metres or radians), converted from the action slot by the manifest's gripper map,
as deploy sim's gripper controller converts them.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import DeployScene
from openral_core.real_wiring import Ros2ControlWiring
from openral_hal.errors import ConfigurationError, EStopLatched, NotConnected
from openral_hal.factory import RealOptions
from openral_hal.realtime import answer_first
from openral_mujoco.action import validated_action
from openral_mujoco.state import FloatArray, JointStateSample

from openral_real.driver_gripper import gripper_map
from openral_real.kinematic_twin import twin_for
from openral_real.manifest_arm import ManifestArm
from openral_real.ros2_control_link import JointReading, Ros2ControlLink, driver_namespace

CONNECT_TIMEOUT_S = 10.0
"""Longest wait at connect for a reading of every joint and the driver's controllers [s]."""
STALE_PERIODS = 2
"""Control periods without a fresh reading after which the E-stop latches."""
SLACK = 1.05
"""A goal's time is this much more than the velocity limits need from the measured pose."""
STEADY_READINGS = 5
"""Readings connect waits for (the newest fresh) before it counts the stream as steady."""


def ros2_control_hal(
    robot: LoadedRobot, transport: str | None, options: RealOptions
) -> Ros2ControlHal:
    """The ``ros2_control`` real driver (the ``openral.real_drivers`` entry point)."""
    return Ros2ControlHal(robot, driver_namespace(transport), options.twin_scene)


class Ros2ControlHal(ManifestArm):
    """A ros2_control robot driver as a real HAL (see the module doc)."""

    is_real = True

    def __init__(
        self, robot: LoadedRobot, namespace: str, twin_scene: DeployScene | None = None
    ) -> None:
        """Wire the HAL; nothing is opened until :meth:`connect`.

        Raises:
            ConfigurationError: The manifest's real driver is not ros2_control.
        """
        real = robot.tables.real
        if real is None or real.ros2_control is None:
            raise ConfigurationError(f"{robot.name} has no ros2_control driver (real.driver)")
        self.robot, self.real, self.namespace = robot, real, namespace
        self.wiring: Ros2ControlWiring = real.ros2_control
        self.on_cycle: Callable[[], None] | None = None
        self.on_fault: Callable[[str], None] = lambda line: None
        self.defer_cycle = False
        self.writes_after_tick = False
        """True while the graph's tick writes each cycle (see WritesAfterTick)."""
        self.estop_reason: str | None = None
        self.sent = 0
        """Trajectories sent to the driver."""
        self._gripper = gripper_map(robot, self.wiring)
        self.attach_twin(twin_for(robot, twin_scene))
        self._link: Ros2ControlLink | None = None
        self._envelope = self.manifest_envelope()
        self._speeds = np.array([float(j.velocity_limit) for j in robot.description.joints])
        self._lock, self._write_gate = threading.Lock(), threading.RLock()
        self._latest: JointStateSample | None = None
        self._last_stamp_s, self._received_s, self._readings = -1.0, 0.0, 0
        self._running = False
        self._gripper_sent: float | None = None
        self._watchdog: threading.Thread | None = None

    # -- what the HAL is ---------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        """True between :meth:`connect` and :meth:`disconnect`."""
        return self._link is not None

    # -- lifecycle ---------------------------------------------------------------------------

    def connect(self) -> None:
        """Open the link, wait for every joint's reading and the controllers, and hold the
        arm where it is measured (nothing is sent before).

        Raises:
            ConfigurationError: No reading of every joint, or no controller, within
                :data:`CONNECT_TIMEOUT_S` (one line naming what is missing).
        """
        with self._lock:
            self._latest, self._last_stamp_s, self._readings = None, -1.0, 0
        link = Ros2ControlLink(self.wiring, self.namespace, self._reading)
        link.open()
        try:
            self._wait_for_driver(link)
        except BaseException:
            link.close()
            raise
        self._link = link
        self.quicker_switches(True)
        self._estopped, self.estop_reason = False, None
        self._envelope.start(self._measured())
        if not self.defer_cycle:
            self.start_cycle()

    def start_cycle(self) -> None:
        """Start writing, and latching on a stream that stops, judged from now: until then
        (a :attr:`defer_cycle` connect) the graph's build may stall the process (idempotent)."""
        if self._running or self._link is None:
            return
        with self._lock:
            self._received_s = max(self._received_s, time.monotonic())
        self._running = True
        self._start_watchdog()

    def disconnect(self) -> None:
        """Hold the measured pose, then close the link (idempotent)."""
        link, self._link = self._link, None
        self._running = False
        if link is None:
            return
        if self._latest is not None:
            self._send_hold(link)
        link.close()
        self.quicker_switches(False)
        if self._watchdog is not None:
            self._watchdog.join(2.0)
            self._watchdog = None

    # -- state and commands ------------------------------------------------------------------

    def read_state(self) -> JointStateSample:
        """The newest reading of every joint in manifest units, stamped as the driver
        stamped it; flagged stale (and the E-stop latched) past two control periods."""
        if self._link is None:
            raise NotConnected("the ros2_control HAL is not connected")
        return self._newest()

    def _newest(self) -> JointStateSample:
        """The newest reading, flagged stale past :data:`STALE_PERIODS` (one was taken)."""
        with self._lock:
            sample, received_s = self._latest, self._received_s
        assert sample is not None
        stale = time.monotonic() - received_s > STALE_PERIODS * self.control_period_s
        return sample._replace(stale=stale)

    def measured_angles(self) -> FloatArray:
        """Every joint in the newest reading [rad or m] (the gripper in its joint's units)."""
        return self._measured()

    def hold_action(self) -> FloatArray:
        """The action that holds the arm where it was last measured (never zeros)."""
        return self.read_state().positions.copy()

    def send_action(self, action: object) -> None:
        """Aim at ``action`` (one value per joint, manifest units); each cycle moves the
        goal there within the envelope.

        Raises:
            ActionRejected: Wrong width, non-finite, or all zeros. EStopLatched.
        """
        if self._link is None:
            raise NotConnected("the ros2_control HAL is not connected")
        values = validated_action(np.asarray(action, dtype=np.float64), self.action_names)
        self.screen_action(values)
        self._envelope.aim(self._joint_values(values))

    @property
    def clamped(self) -> npt.NDArray[np.int64]:
        """Commands clamped into the position limits, per joint."""
        return self._envelope.clamped.copy()

    # -- the E-stop --------------------------------------------------------------------------

    def latch_fault(self, reason: str) -> None:
        """Latch the E-stop because of a fault and say why in one line (once)."""
        if self._estopped:
            return
        self.estop_reason = reason
        self.estop()
        self.on_fault(f"E-stop latched: {reason}; nothing moves until it is released")

    def _on_latch(self) -> None:
        """Hold at the measured pose, cancel the gripper's goal; nothing more is sent."""
        self.estop_reason = self.estop_reason or "requested"
        link = self._link
        with self._write_gate:  # a goal already under way goes out before the hold
            if link is not None and self._latest is not None:
                self._send_hold(link)
                link.cancel_gripper()

    def _on_release(self) -> None:
        """Start again from the measured pose, slowly (a stale stream stays latched)."""
        if self._link is not None and self.read_state().stale:
            raise EStopLatched("the robot driver's readings are stale; release refused")
        self._envelope.start(self._measured())
        self._gripper_sent, self.estop_reason = None, None

    # -- frames ------------------------------------------------------------------------------

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        """The kinematic twin's (model, data), posed by :meth:`pose_twin`."""
        return (self._twin.model, self._twin.data) if self._twin is not None else None

    def pose_twin(self, sample: JointStateSample) -> None:
        """Put the twin at ``sample``'s joints (the gripper's fingers at its joint's
        position), as of its stamp."""
        if self._twin is None:
            return
        rates = sample.velocities.copy()
        if self._gripper is not None:
            slot, axis = self._gripper
            rates[slot] /= axis.gain
        angles = self._joint_values(sample.positions)
        self._twin.pose(angles, rates, sample.efforts, sample.stamp_ns / 1e9)

    # -- internals ---------------------------------------------------------------------------

    def _reading(self, reading: JointReading) -> None:
        """One joint state of the driver (link thread): store it, run the hook, write."""
        values, stamp_s = reading
        names = self.wiring.driver_joints
        if any(name not in values for name in names):
            return  # another broadcaster's message, or a partial one: not a reading of ours
        if stamp_s <= self._last_stamp_s:
            return  # a stamp that does not advance is no fresh reading
        sample = self._sample(values, stamp_s)
        with self._lock:
            self._latest, self._last_stamp_s = sample, stamp_s
            self._received_s = time.monotonic()
            self._readings += 1
        if not self._running or self._link is None:
            return
        if self.on_cycle is not None:
            self.on_cycle()
        if not self.writes_after_tick:
            self.write_cycle()

    def _sample(
        self, values: dict[str, tuple[float, float, float]], stamp_s: float
    ) -> JointStateSample:
        rows = np.array([values[name] for name in self.wiring.driver_joints], dtype=np.float64)
        positions, velocities = rows[:, 0].copy(), rows[:, 1].copy()
        if self._gripper is not None:
            slot, axis = self._gripper
            positions[slot] = axis.slot(positions[slot])
            velocities[slot] *= axis.gain
        efforts = rows[:, 2].copy()
        return JointStateSample(
            self.joint_names, positions, velocities, efforts, round(stamp_s * 1e9), None, False
        )

    def write_cycle(self) -> None:
        """Send this cycle's goal (nothing while the E-stop is latched or unconnected)."""
        link = self._link
        with self._write_gate:  # the latch is read and the goal sent as one step
            if link is not None and self._running and not self._estopped:
                self._write(link)

    def _write(self, link: Ros2ControlLink) -> None:
        """Send the next goal, reached no sooner than the velocity limits allow from the
        measured pose (a controller that lags is never asked for a faster move)."""
        goal, arm = self._envelope.step(), self._arm_slots()
        names = [self.wiring.driver_joints[i] for i in arm]
        gap = np.abs(goal[arm] - self._measured()[arm])
        after_s = max(self.control_period_s, float(np.max(gap / self._speeds[arm])) * SLACK)
        link.send_point(names, goal[arm], after_s)
        self.sent += 1
        if self._gripper is not None and self.wiring.gripper_action is not None:
            slot = self._gripper[0]
            target = float(self._envelope.target[slot])
            if self._gripper_sent is None or abs(target - self._gripper_sent) > 1e-9:
                effort = float(self.description.joints[slot].effort_limit)
                link.send_gripper(target, effort)
                self._gripper_sent = target

    def _send_hold(self, link: Ros2ControlLink) -> None:
        measured = self._measured()
        arm = self._arm_slots()
        link.send_point(
            [self.wiring.driver_joints[i] for i in arm], measured[arm], self.control_period_s
        )

    def _arm_slots(self) -> list[int]:
        """The slots the trajectory controller takes (all but a gripper with its action)."""
        skip = self._gripper[0] if self._gripper and self.wiring.gripper_action else None
        return [i for i in range(len(self.joint_names)) if i != skip]

    def _measured(self) -> FloatArray:
        """The newest reading in joint units (the gripper's slot back in its joint's)."""
        return self._joint_values(self._newest().positions)

    def _joint_values(self, slots: FloatArray) -> FloatArray:
        """Action-slot values (or a reading's positions) in joint units: the gripper's slot
        through the inverse of its reading map."""
        joints = np.asarray(slots, dtype=np.float64).copy()
        if self._gripper is not None:
            slot, axis = self._gripper
            joints[slot] = axis.joint(joints[slot])
        return joints

    def _wait_for_driver(self, link: Ros2ControlLink) -> None:
        deadline = time.monotonic() + CONNECT_TIMEOUT_S
        while time.monotonic() < deadline:  # a steady stream: fresh after a few readings
            steady = self._readings >= STEADY_READINGS and not self._newest().stale
            if steady and link.driver_ready() is None:
                return
            time.sleep(0.02)
        topic = link.name(self.wiring.joint_state_topic)
        what = (
            f"no reading of {', '.join(self.wiring.driver_joints)} on {topic}"
            if self._latest is None
            else str(link.driver_ready())
        )
        raise ConfigurationError(
            f"the robot driver in namespace {self.namespace or '/'} did not answer within "
            f"{CONNECT_TIMEOUT_S:g} s: {what} (is it running, on this ROS_DOMAIN_ID?)"
        )

    def _start_watchdog(self) -> None:
        """A thread that wakes when the newest reading turns :data:`STALE_PERIODS` periods
        old and, if none came meanwhile, latches the E-stop. A stream that ended may start
        again on a clock of its own (a restarted driver): its first stamp is taken."""

        def watch() -> None:
            answer_first()
            period = self.control_period_s
            while self._link is not None:
                with self._lock:
                    age_s = time.monotonic() - self._received_s
                if age_s < STALE_PERIODS * period:
                    time.sleep(STALE_PERIODS * period - age_s)
                    continue
                with self._lock:
                    self._last_stamp_s = -math.inf
                if not self._estopped and self._link is not None:
                    self.latch_fault(
                        f"the robot driver's {self.wiring.joint_state_topic} stopped "
                        f"({age_s * 1000:.0f} ms without a fresh reading, control period "
                        f"{period * 1000:g} ms)"
                    )
                time.sleep(period)

        self._watchdog = threading.Thread(target=watch, name="openral-ros2-watchdog", daemon=True)
        self._watchdog.start()

    @property
    def received_s(self) -> float:
        """When the newest reading arrived [s, ``time.monotonic()``]."""
        with self._lock:
            return self._received_s

    @property
    def readings(self) -> int:
        """Fresh readings taken since :meth:`connect` (each one writes a goal while running)."""
        with self._lock:
            return self._readings
