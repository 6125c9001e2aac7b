"""The HAL contract as typing Protocols: what every HAL does, and what some can do more.

Every HAL (:class:`RobotHal`) connects, reports joint state, takes actions in its action
spec's slots, and latches an E-stop. Capabilities are separate Protocols, checked with
``isinstance`` (all are ``runtime_checkable``), never with ``getattr``:

* :class:`CameraHal` renders the manifest's RGB sensors;
* :class:`Tickable` is advanced by a control loop, one control period per tick (simulated
  HALs only; a real HAL never is);
* :class:`CycledHal` is a real HAL with a loop of its own (read, a hook, write, once per
  control period), which a graph's control step rides on instead of ticking it; a
  :class:`TwinHal` also poses a model of the robot at each reading (its frames), and an
  :class:`ActionScreen` says at once whether it would refuse an action;
* :class:`MujocoBacked` exposes the live MuJoCo model and data;
* :class:`MobileBaseHal` drives a mobile base with velocity commands and reports its
  odometry (when its ``base`` is not None);
* :class:`FramesHal` knows the TF frames of the robot and its sensors in its MuJoCo model
  (:class:`~openral_sim.frame_tree.FrameTree`), read from its ``mujoco_handles``;
* :class:`ObservingHal` keeps the typed observation of its scene's last step;
* the sensor sources of :mod:`openral_sim.sensor_sources` (re-exported here):
  :class:`CameraSource`, :class:`DepthSource`, :class:`LidarSource`,
  :class:`StateSensorSource` and :class:`BaseOdometrySource` — what the ROS sensor
  bridges depend on, so a real driver that implements them publishes its depth, scans and
  IMU through the same bridges a simulation does.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import RobotDescription
from openral_mujoco.state import FloatArray, JointStateSample
from openral_sim.base_drive import BaseCommand, BaseDrive, BaseOdometry
from openral_sim.frame_tree import FrameTree
from openral_sim.observation import Observation
from openral_sim.sensor_sources import (
    BaseOdometrySource,
    CameraSource,
    DepthSource,
    LidarSource,
    StateSensorSource,
)

from openral_hal.estop import EStopLatch


@runtime_checkable
class RobotHal(Protocol):
    """The core calls every HAL answers, simulated or real."""

    @property
    def is_real(self) -> bool:
        """True for real hardware (never ticked by a control loop, never attached to a scene)."""
        ...

    @property
    def description(self) -> RobotDescription:
        """The manifest this HAL was built from."""
        ...

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Canonical joint names, in manifest order (the order of every joint state)."""
        ...

    @property
    def connected(self) -> bool:
        """True between :meth:`connect` and :meth:`disconnect`."""
        ...

    def connect(self) -> None:
        """Load or open the robot and hold its start pose."""
        ...

    def disconnect(self) -> None:
        """Release the robot."""
        ...

    def read_state(self) -> JointStateSample:
        """Every manifest joint, in manifest order and manifest units."""
        ...

    @property
    def action_names(self) -> tuple[str, ...]:
        """One name per action slot (the manifest joints on every native path)."""
        ...

    def hold_action(self) -> FloatArray:
        """The action that keeps the robot where it is commanded to be now."""
        ...

    def send_action(self, action: object) -> None:
        """Command one action (``len(action_names)`` finite values); refused actions change
        nothing."""
        ...

    @property
    def estopped(self) -> bool:
        """True while the E-stop is latched."""
        ...

    def estop(self) -> None:
        """Latch the E-stop: actions are refused and the robot is held."""
        ...

    def release_estop(self) -> None:
        """Unlatch the E-stop without moving the robot."""
        ...


@runtime_checkable
class CameraHal(RobotHal, Protocol):
    """A HAL that renders the manifest's RGB sensors."""

    def read_images(self) -> dict[str, npt.NDArray[np.uint8]]:
        """Last frame (H x W x 3, uint8) of each RGB sensor, by sensor name."""
        ...

    def camera_fovy_deg(self, sensor: str) -> float | None:
        """Vertical field of view of the camera that renders ``sensor`` [deg], if known."""
        ...


@runtime_checkable
class Tickable(RobotHal, Protocol):
    """A simulated HAL that a control loop advances in fixed control periods (a real HAL
    never is: its hardware keeps time)."""

    @property
    def control_period_s(self) -> float:
        """Simulated time one :meth:`tick` advances [s]."""
        ...

    def tick(self, action: object | None, *, glide: bool = False) -> bool:
        """Apply ``action`` (None: hold what is commanded now) and advance one control
        period; False (nothing done) while E-stopped. With ``glide`` the action is the next
        sample of a smooth path: the joints move to it at constant speed over the period,
        with that speed fed forward (when the HAL's action slots are its joints).

        Raises:
            ActionRejected: ``action`` is malformed; nothing is changed.
        """
        ...

    def reset(self) -> str:
        """Put the scene back where it started (its seed, the start pose, every object);
        the E-stop latch is kept as it is. Returns what was reset, in one line."""
        ...


@runtime_checkable
class StateParted(Protocol):
    """A tickable HAL that can also step a control period in ``state_parts`` equal parts
    (a native scene at its ``state_rate_hz``): :meth:`tick_part` with an action starts a
    new period; with None it steps the next part of the period in force."""

    @property
    def state_parts(self) -> int:
        """Parts per control period (1: a part is a whole period)."""
        ...

    def tick_part(self, action: object | None, *, glide: bool = False) -> bool:
        """One part of a control period (see the class doc); False while E-stopped."""
        ...


@runtime_checkable
class MujocoBacked(Protocol):
    """A HAL whose robot lives in a MuJoCo model it can hand out."""

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        """The live (model, data), or None when the backend is not MuJoCo."""
        ...


__all__ = [
    "ActionScreen",
    "BaseOdometrySource",
    "CameraHal",
    "CameraSource",
    "CycledHal",
    "DepthSource",
    "EStopLatch",
    "FramesHal",
    "LidarSource",
    "MobileBaseHal",
    "MujocoBacked",
    "ObservingHal",
    "PathScreen",
    "RobotHal",
    "StateSensorSource",
    "Tickable",
    "TwinHal",
]


@runtime_checkable
class ObservingHal(RobotHal, Protocol):
    """A HAL that keeps the typed observation of its scene's last step or reset."""

    def last_observation(self) -> Observation:
        """The latest observation (its sensor frames: those due at that step).

        Raises:
            NotConnected: Before connect.
        """
        ...


@runtime_checkable
class MobileBaseHal(RobotHal, BaseOdometrySource, Protocol):
    """A HAL that may carry a mobile base (``base`` None: this robot has none)."""

    @property
    def base(self) -> BaseDrive | None:
        """The base's drive, or None."""
        ...

    def command_base(self, vx_m_s: float, vy_m_s: float, wz_rad_s: float) -> BaseCommand:
        """Drive at this base-frame velocity [m/s, m/s, rad/s] (clamped to the limits).

        Raises:
            EStopLatched: The E-stop is latched. ActionRejected: A non-finite value.
        """
        ...

    def base_odometry(self) -> BaseOdometry:
        """The base's pose in the odometry frame and twist in the base frame now."""
        ...


@runtime_checkable
class FramesHal(MujocoBacked, Protocol):
    """A simulated HAL whose robot and sensor frames can be read from its MuJoCo data."""

    def frame_tree(self) -> FrameTree | None:
        """The TF frames (None: this backend has none), laid out once.

        Raises:
            HalError: The model's layout cannot be stated as a tree.
        """
        ...


@runtime_checkable
class CycledHal(RobotHal, Protocol):
    """A real HAL whose own loop reads the robot, runs :attr:`on_cycle`, then writes the
    command, once per control period (as ros2_control's read, update, write)."""

    @property
    def control_period_s(self) -> float:
        """One cycle of the HAL's loop [s]."""
        ...

    on_cycle: Callable[[], None] | None
    """Run on the loop's thread after each read, before the write (None: nothing)."""
    on_fault: Callable[[str], None]
    """Called once, with one line, when a fault latches the E-stop."""
    defer_cycle: bool
    """True: :meth:`connect` holds the robot where it is and leaves the loop to
    :meth:`start_cycle` (a caller with more to build first); readings stay the connect's
    until then."""

    def start_cycle(self) -> None:
        """Start the loop after a deferred connect (idempotent)."""
        ...


@runtime_checkable
class WritesAfterTick(Protocol):
    """A :class:`CycledHal` whose write may wait for the graph's tick on its reading (a
    robot driver that keeps time itself: a command written a tick later is only later,
    never missing), so an action taken at the tick reaches the robot in the same cycle."""

    writes_after_tick: bool
    """True while the graph writes (:meth:`write_cycle` after each tick); False: the HAL's
    own cycle writes right after :attr:`CycledHal.on_cycle`."""

    def write_cycle(self) -> None:
        """Write this cycle's command (nothing while the E-stop is latched)."""
        ...


@runtime_checkable
class TwinHal(Protocol):
    """A HAL that keeps a model of its robot posed at the measured joints."""

    def pose_twin(self, sample: JointStateSample) -> None:
        """Pose the model at the reading ``sample`` came from."""
        ...


@runtime_checkable
class PathScreen(Protocol):
    """A real HAL with a twin scene: it can tell where a joint path would touch it."""

    def path_contact(self, rows: FloatArray) -> str | None:
        """Where the path from the measured pose through ``rows`` (action values, one row
        per point) first touches the scene's fixed geometry, in one line naming the pair;
        None: nowhere (or no scene)."""
        ...


@runtime_checkable
class ActionScreen(Protocol):
    """A HAL that can say, before an action is queued, that it would refuse it."""

    def screen_action(self, values: FloatArray) -> None:
        """Nothing when ``values`` (validated: width, finite) would be taken.

        Raises:
            ActionRejected: The HAL refuses it (the message says why). EStopLatched.
        """
        ...
