"""FeetechHal: a Feetech servo arm (LeRobot's SO-100, SO-101) as a real RobotHal.

Everything robot-specific comes from the manifest's tables (the bus, the motors, the
envelope) and the arm's calibration file (:mod:`openral_real.calibration`). The safety
rules of a real HAL:

- it is never ticked and never attached to a scene (it has no ``tick``; ``build_hal``
  refuses a scene in ``real`` mode); its own loop (:class:`~openral_real.bus_cycle.BusCycle`)
  keeps time;
- connecting reads the arm before it writes anything: the calibration file, every motor's
  answer and model, the calibration registers, the present positions; then it writes the
  goals *where the arm is* (to the step) before it turns torque on, so nothing jumps;
- hold is the last measured position, never zero; an all-zero action is refused (unless
  the manifest allows it); every command passes the position and velocity envelope, and the
  first motion after connect or release is slower still
  (:class:`~openral_real.motion_envelope.MotionEnvelope`);
- the E-stop latches on request, on a bus fault and on a stale reading (see the loop), and
  nothing is written after it but its effect (``estop``: hold with torque on, or torque
  off); release starts again from the measured pose;
- disconnecting (Ctrl-C, SIGTERM through ``deploy real``) holds the measured pose, then
  leaves torque as the manifest's ``shutdown`` says.
"""

from __future__ import annotations

import gc
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import RgbSensor
from openral_core.real_wiring import FeetechWiring, RealWiring
from openral_hal.errors import ConfigurationError, NotConnected
from openral_hal.factory import RealOptions
from openral_mujoco.action import validated_action
from openral_mujoco.state import FloatArray, JointStateSample

from openral_real.bus_bringup import bring_up
from openral_real.bus_cycle import BusCycle, CycleTimes
from openral_real.calibration import (
    calibration_path,
    joint_scales,
    read_calibration,
)
from openral_real.errors import BusError, BusFault
from openral_real.feetech_bus import FeetechBus, ServoReading
from openral_real.kinematic_twin import KinematicTwin, twin_for
from openral_real.manifest_arm import ManifestArm
from openral_real.motion_envelope import MotionEnvelope
from openral_real.opencv_cameras import Cameras, camera_devices
from openral_real.servo_units import ServoUnits


@dataclass(frozen=True)
class _Session:
    """What a connected HAL holds."""

    bus: FeetechBus
    cycle: BusCycle
    units: ServoUnits
    envelope: MotionEnvelope
    twin: KinematicTwin | None
    cameras: Cameras


def feetech_hal(robot: LoadedRobot, transport: str | None, options: RealOptions) -> FeetechHal:
    """The ``feetech`` real driver (the ``openral.real_drivers`` entry point)."""
    if not transport:
        raise ConfigurationError(
            f"{robot.name}: the feetech driver needs the bus's serial port (--transport "
            "/dev/ttyACM0, or an emulator's /dev/pts/N from: openral sim bus ROBOT)"
        )
    return FeetechHal(robot, transport, options)


class FeetechHal(ManifestArm):
    """A Feetech servo arm, driven through the manifest (see the module doc)."""

    is_real = True

    def __init__(self, robot: LoadedRobot, port: str, options: RealOptions | None = None) -> None:
        """Wire the HAL; nothing is opened until :meth:`connect`.

        Raises:
            ConfigurationError: The manifest has no feetech bus.
        """
        real, bus = _bus_of(robot)
        self.robot, self.port, self.real, self.bus_wiring = robot, port, real, bus
        self.options = options or RealOptions()
        self.calibration_file = calibration_path(
            robot.name, bus, self.options.arm_id, self.options.calibration_file
        )
        self.estop_reason: str | None = None
        """Why the E-stop latched (None while released)."""
        self.estop_at: float | None = None
        """When it latched [s, system clock] (None while released)."""
        self.on_fault: Callable[[str], None] = _say
        """Called once, on the bus's thread, with the line that says why a fault latched."""
        self.defer_cycle = False
        """True: :meth:`connect` holds the arm and leaves the loop to :meth:`start_cycle`."""
        self._rgb = {s.name: s for s in robot.description.sensors if isinstance(s, RgbSensor)}
        self._devices = camera_devices(self._rgb, self.options.cameras)
        self._session: _Session | None = None
        self.attach_twin(twin_for(robot, self.options.twin_scene))  # frames known at once
        _one_source_per_camera(self._devices, self.camera_sensors())
        self._froze = False
        """While connected, the heap found at connect is frozen out of garbage collection
        (``gc.freeze``, unless the process froze it itself, as deploy real does): a full
        collection of it holds Python's lock for tens of milliseconds."""

    # -- what the HAL is ---------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        """True between :meth:`connect` and :meth:`disconnect`."""
        return self._session is not None

    @property
    def times(self) -> CycleTimes:
        """When the bus cycles ran (lateness, round trips)."""
        return self._running().cycle.times

    # -- lifecycle ---------------------------------------------------------------------------

    def connect(self) -> None:
        """Read the arm, hold it where it is with torque on, and start the bus's loop.

        Raises:
            CalibrationError: The calibration file is missing or another arm's.
            BusError: The port cannot be opened, a motor is missing or of another model,
                the servos hold another calibration, or a motor reports a fault; nothing
                was written to the bus. CameraError: A camera device does not open.
        """
        self._froze = not gc.get_freeze_count()
        if self._froze:  # a full collection of the heap would stall the bus's loop for ms
            gc.collect()
            gc.freeze()
        try:
            bus, cameras, units, readings = self._bring_up()
        except BaseException:
            self._thaw()
            raise
        envelope = self.manifest_envelope()
        envelope.start(units.angles(readings))
        cycle = BusCycle(
            bus, units, envelope, self, self.control_period_s, self.real.estop == "torque_off"
        )
        cycle.seed(readings)
        self._estopped, self.estop_reason = False, None
        self._session = _Session(bus, cycle, units, envelope, self._twin, cameras)
        self.quicker_switches(True)
        if not self.defer_cycle:
            cycle.start()

    def start_cycle(self) -> None:
        """Start the bus's loop after a :attr:`defer_cycle` connect (idempotent)."""
        cycle = self._running().cycle
        if not cycle.running:
            cycle.start()

    def disconnect(self) -> None:
        """Stop the loop, hold the measured pose, then leave torque as ``shutdown`` says."""
        session, self._session = self._session, None
        if session is None:
            return
        session.cycle.stop()
        bus = session.bus
        try:
            present = [r.position for r in bus.read_present()]
            bus.write_goals(present)
            if self.real.shutdown == "torque_off":
                bus.write_all("Torque_Enable", [0] * len(present))
        except BusFault:
            pass  # a bus that failed cannot be told anything more
        bus.close()
        session.cameras.close()
        self.quicker_switches(False)
        self._thaw()

    # -- state and commands ------------------------------------------------------------------

    def read_state(self) -> JointStateSample:
        """The newest reading of every joint, in manifest units, stamped with the system clock
        when it was read; a reading older than two control periods is flagged stale and
        latches the E-stop."""
        _, sample, age_s = self._running().cycle.latest()
        stale = age_s > 2 * self.control_period_s
        if stale and not self._estopped:
            self.latch_fault(
                f"the newest reading of the bus is {age_s * 1000:.0f} ms old (control period "
                f"{self.control_period_s * 1000:g} ms)"
            )
        return sample._replace(stale=stale)

    def measured_angles(self) -> FloatArray:
        """Every joint's angle [rad] in the newest reading (a gripper's jaw angle)."""
        session = self._running()
        readings, _, _ = session.cycle.latest()
        return session.units.angles(readings)

    def hold_action(self) -> FloatArray:
        """The action that holds the arm where it was last measured (never zeros)."""
        return self._running().units.action_of(self.measured_angles())

    def send_action(self, action: object) -> None:
        """Aim the arm at ``action`` (one value per joint, manifest units); the bus's loop
        moves the goals there within the envelope.

        Raises:
            ActionRejected: Wrong width, a non-finite value, or all zeros (see the module
                doc); nothing changes. EStopLatched: The E-stop is latched.
        """
        session = self._running()
        values = validated_action(np.asarray(action, dtype=np.float64), self.action_names)
        self.screen_action(values)
        session.envelope.aim(session.units.action_angles(values))

    @property
    def clamped(self) -> npt.NDArray[np.int64]:
        """Commands clamped into the position limits, per joint."""
        return self._running().envelope.clamped.copy()

    # -- the E-stop --------------------------------------------------------------------------

    def latch_fault(self, reason: str) -> None:
        """Latch the E-stop because of a fault, and say why in one line (once)."""
        if self._estopped:
            return
        self.estop_reason, self.estop_at = reason, time.time()
        self._estopped = True
        self.on_fault(f"E-stop latched: {reason}; nothing moves until it is released")

    def _on_latch(self) -> None:
        """A requested E-stop: its effect is written by the next cycle, started at once."""
        self.estop_reason = self.estop_reason or "requested"
        self.estop_at = self.estop_at or time.time()
        if self._session is not None:
            self._session.cycle.effect_pending = True
            self._session.cycle.settle_latch()
            self._session.cycle.wake()

    def _on_release(self) -> None:
        """Start again from the measured pose, slowly; torque back on if it was cut."""
        session = self._running()
        session.envelope.start(self.measured_angles())
        if self.real.estop == "torque_off":
            session.cycle.torque_on_pending = True
        self.estop_reason = self.estop_at = None

    # -- frames and cameras ------------------------------------------------------------------

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        """The kinematic twin's (model, data), posed by :meth:`pose_twin`."""
        twin = self._session.twin if self._session is not None else None
        return (twin.model, twin.data) if twin is not None else None

    def pose_twin(self, sample: JointStateSample) -> None:
        """Put the twin at the joints of the newest reading, as of ``sample``'s stamp."""
        session = self._running()
        if session.twin is not None:
            readings, _, _ = session.cycle.latest()
            angles, rates, efforts = session.units.physical(readings)
            session.twin.pose(angles, rates, efforts, sample.stamp_ns / 1e9)

    def read_images(self) -> dict[str, npt.NDArray[np.uint8]]:
        """The newest frame of each camera with a device, by sensor name."""
        return self._session.cameras.frames() if self._session is not None else {}

    def camera_fovy_deg(self, sensor: str) -> float | None:
        """The manifest's vertical field of view of ``sensor`` [deg]."""
        found = self._rgb.get(sensor)
        return float(found.fovy_deg) if found is not None and found.fovy_deg else None

    @property
    def on_cycle(self) -> Callable[[], None] | None:
        """Run by the bus's loop after each read, before its write (the graph's step)."""
        return self._session.cycle.on_cycle if self._session is not None else None

    @on_cycle.setter
    def on_cycle(self, hook: Callable[[], None] | None) -> None:
        self._running().cycle.on_cycle = hook

    # -- internals ---------------------------------------------------------------------------

    def _bring_up(self) -> tuple[FeetechBus, Cameras, ServoUnits, list[ServoReading]]:
        """Calibration, cameras, then the bus brought up (nothing open is left behind when
        one of them fails)."""
        calibration = read_calibration(self.calibration_file, self.description, self.bus_wiring)
        units = ServoUnits(self.robot, joint_scales(self.description, self.bus_wiring, calibration))
        cameras = Cameras(self._rgb, self._devices)
        cameras.open()  # before the bus: a missing camera leaves the arm untouched
        bus = FeetechBus(self.port, self.bus_wiring, self.joint_names)
        try:
            bus.open()
            readings = bring_up(bus, calibration, self._fix_hint())
        except BusFault as error:
            bus.close()
            cameras.close()
            raise BusError(f"{error}; connecting stopped before torque was turned on") from None
        except BaseException:
            bus.close()
            cameras.close()
            raise
        return bus, cameras, units, readings

    def _thaw(self) -> None:
        """Give the heap frozen at connect back to the collector (when this HAL froze it)."""
        if self._froze:
            gc.unfreeze()
            self._froze = False

    def _fix_hint(self) -> str:
        """How to write this HAL's calibration file to the servos (for a refusal)."""
        return (
            f"write {self.calibration_file} to them: openral robot calibrate {self.robot.name} "
            f"--transport {self.port} --apply {self.calibration_file}"
        )

    def _running(self) -> _Session:
        if self._session is None:
            raise NotConnected("the arm is not connected; call connect() first")
        return self._session


def _bus_of(robot: LoadedRobot) -> tuple[RealWiring, FeetechWiring]:
    real = robot.tables.real
    if real is None or real.feetech is None:
        raise ConfigurationError(
            f"{robot.name} has no feetech bus in its manifest (real.feetech); it cannot be "
            "driven by the feetech driver"
        )
    return real, real.feetech


def _one_source_per_camera(devices: Mapping[str, str], rendered: Mapping[str, object]) -> None:
    """Refuse a camera that has a device and is rendered by the twin scene as well.

    Raises:
        ConfigurationError: One line naming the camera.
    """
    both = sorted(set(devices) & set(rendered))
    if both:
        raise ConfigurationError(
            f"camera {both[0]} has a device ({devices[both[0]]}) and the twin scene renders "
            "it too: drop its --camera or use a scene without it"
        )


def _say(line: str) -> None:
    sys.stderr.write(f"openral: {line}\n")
