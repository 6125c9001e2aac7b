"""The simulated arm behind an emulated servo bus: shafts that really move.

Each joint's servo has an encoder: its raw reading is ``zero + angle · steps/rad``, where
``zero`` (the reading at the model's joint angle 0) is where the horn happened to be
mounted, drawn once per arm from a seed so that the joint's whole range reads inside one
turn. A servo with torque on runs its profile (:class:`ServoProfile`) towards its goal and
the simulation's joint is driven to the profile's set point. A servo's position loop is far
stiffer than the model's position actuator (which sags a few hundredths of a radian under
the arm's weight), so the robot alone is simulated with its links' weight compensated
(:func:`servo_held`), as a stiff servo holds it; with torque off the shaft
stays where it is, held by the gearbox's friction (a 1:345 STS3215 gearbox holds a small
arm's links against gravity), unless a hand moves it. The simulation is the robot alone
(:class:`MujocoArmHAL`, stepped in slices of :data:`SLICE_S`) or a scene's HAL (stepped a
control period at a time), advanced against the wall clock on a thread of its own.

A hand can also move a joint (:meth:`EmulatedArm.place`): the joint is put at an angle, as a
user moves an arm whose torque is off (calibration).
"""

from __future__ import annotations

import math
import random
import threading
import time
from dataclasses import dataclass

import mujoco
import numpy as np
from openral_core.loaded import LoadedRobot
from openral_core.models import LimitedJoint
from openral_core.servo_models import ServoModel
from openral_core.tables import robot_tables
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.protocol import Tickable
from openral_hal.realtime import answer_first
from openral_mujoco.gripper import gripper_command, reading_map
from openral_mujoco.state import FloatArray

from openral_real.emulator.servo_motion import ServoProfile

SLICE_S = 0.004
"""Simulated time per physics slice of the robot alone [s] (the servos' positions change
this often)."""
MARGIN_STEPS = 64
"""Steps kept between a joint's range and the ends of the encoder's turn."""


@dataclass(frozen=True)
class Shaft:
    """One servo's shaft at one instant."""

    raw: float
    """Encoder reading [steps] (not wrapped)."""
    speed: float
    """[steps/s]"""
    load: float
    """Share of the stall torque the motor pushes with, -1 to 1."""


@dataclass
class Drive:
    """What one servo's registers ask of its motor."""

    torque: bool = False
    goal_raw: float | None = None
    """Goal in encoder steps (the register's goal plus the homing offset)."""
    max_speed: float = 0.0
    """[steps/s]"""
    acceleration: int = 0


class EmulatedArm:
    """A simulated arm whose joints are driven like servos (see the module doc)."""

    def __init__(
        self, hal: MujocoArmHAL | Tickable, robot: LoadedRobot, model: ServoModel, seed: int = 0
    ) -> None:
        """Wrap a connected HAL; nothing moves until :meth:`start`."""
        self.hal, self.robot, self.model = hal, robot, model
        self.joints = tuple(joint.name for joint in robot.description.joints)
        self.steps_per_rad = model.resolution / (2.0 * math.pi)
        self.zero = _encoder_zeros(robot, self.steps_per_rad, model.resolution, seed)
        self.drives = [Drive() for _ in self.joints]
        self._gripper_maps = _gripper_maps(robot)
        angles = self._angles()
        self._profiles = [ServoProfile(self.raw_of(i, a)) for i, a in enumerate(angles)]
        self._shafts = self._read_shafts()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # -- conversions -------------------------------------------------------------------------

    def raw_of(self, index: int, angle: float) -> float:
        """Encoder reading of joint ``index`` at ``angle`` [rad]."""
        return self.zero[index] + angle * self.steps_per_rad

    def angle_of(self, index: int, raw: float) -> float:
        """Angle [rad] of joint ``index`` at encoder reading ``raw``."""
        return (raw - self.zero[index]) / self.steps_per_rad

    # -- the bus's side ----------------------------------------------------------------------

    def shafts(self) -> list[Shaft]:
        """Every shaft now (thread-safe)."""
        with self._lock:
            return list(self._shafts)

    def drive(self, index: int, drive: Drive) -> None:
        """What servo ``index``'s registers ask of it from now on."""
        with self._lock:
            self.drives[index] = drive

    def place(self, joint: str, angle: float) -> None:
        """A hand puts ``joint`` at ``angle`` [rad] (the robot alone only).

        Raises:
            ValueError: An unknown joint, or a scene's arm (no hand reaches into a scene).
        """
        if joint not in self.joints:
            raise ValueError(f"no joint {joint!r}; joints: {', '.join(self.joints)}")
        if not isinstance(self.hal, MujocoArmHAL):
            raise ValueError("only the robot alone can be moved by hand, not a scene's arm")
        index = self.joints.index(joint)
        with self._lock:
            model, data = self.hal.mujoco_handles()
            data.qpos[self.hal.wiring.joint_qpos_addr[joint]] = angle
            data.qvel[self.hal.wiring.joint_qvel_addr[joint]] = 0.0
            mujoco.mj_forward(model, data)
            self.hal.driver.hold_current_pose(data)
            self._profiles[index].hold(self.raw_of(index, angle))
            self._shafts = self._read_shafts()

    # -- the clock ---------------------------------------------------------------------------

    def start(self) -> None:
        """Advance the simulation against the wall clock on a thread of its own."""
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="emulated-arm", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the clock (idempotent)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5.0)
            self._thread = None

    def advance(self, dt_s: float) -> None:
        """Run every servo's profile for ``dt_s`` and step the simulation that long."""
        with self._lock:
            targets = np.empty(len(self.joints))
            for i, (drive, profile) in enumerate(zip(self.drives, self._profiles, strict=True)):
                if drive.torque and drive.goal_raw is not None:
                    raw = profile.follow(drive.goal_raw, dt_s, drive.max_speed, drive.acceleration)
                else:
                    profile.hold()
                    raw = profile.setpoint
                targets[i] = self.angle_of(i, raw)
            self._step(self._action(targets), dt_s)
            self._shafts = self._read_shafts()

    def _run(self) -> None:
        answer_first()  # it holds Python's lock the bus's answering thread waits for
        period = SLICE_S if isinstance(self.hal, MujocoArmHAL) else self._period()
        deadline = time.monotonic()
        while not self._stop.is_set():
            deadline += period
            wait = deadline - time.monotonic()
            if wait > 0:
                self._stop.wait(wait)
            elif wait < -10 * period:  # far behind (a stalled machine): do not catch up
                deadline = time.monotonic()
            self.advance(period)

    def _period(self) -> float:
        assert isinstance(self.hal, Tickable)
        return float(self.hal.control_period_s)

    def _step(self, action: FloatArray, dt_s: float) -> None:
        hal = self.hal
        if isinstance(hal, MujocoArmHAL):
            _, data = hal.mujoco_handles()
            hal.driver.command(action, data, glide_s=dt_s)
            timestep = float(hal.mujoco_handles()[0].opt.timestep)
            hal.step(max(1, round(dt_s / timestep)))
        else:
            hal.tick(action, glide=True)

    # -- manifest units ----------------------------------------------------------------------

    def _angles(self) -> FloatArray:
        """Every joint's angle [rad] (a gripper's value read back into its jaw angle)."""
        values = np.array(self.hal.read_state().positions, dtype=np.float64)
        for index, (offset, weight, _, _) in self._gripper_maps.items():
            values[index] = (values[index] - offset) / weight
        return values

    def _action(self, angles: FloatArray) -> FloatArray:
        """The manifest action that drives every joint to ``angles`` [rad]."""
        action = angles.copy()
        for index, (_, _, mode, ctrl_range) in self._gripper_maps.items():
            action[index] = gripper_command(mode, float(angles[index]), ctrl_range)
        return action

    def _read_shafts(self) -> list[Shaft]:
        state = self.hal.read_state()
        angles = self._angles()
        shafts = []
        for i in range(len(self.joints)):
            speed = float(state.velocities[i])
            if i in self._gripper_maps:
                speed /= self._gripper_maps[i][1]
            limit = self.robot.description.joints[i].effort_limit
            load = float(state.efforts[i]) / limit if limit else 0.0
            shafts.append(
                Shaft(self.raw_of(i, angles[i]), speed * self.steps_per_rad, max(-1, min(1, load)))
            )
        return shafts


def servo_held(robot: LoadedRobot) -> LoadedRobot:
    """``robot`` with its model's gravity compensated (``sim.gravity_compensation``), the way
    its servos' stiff position loops hold its links up."""
    sim = robot.description.sim
    if sim is None or sim.gravity_compensation:
        return robot
    held = robot.description.model_copy(
        update={"sim": sim.model_copy(update={"gravity_compensation": True})}
    )
    return LoadedRobot(held, robot.folder, robot_tables(held))


def _encoder_zeros(
    robot: LoadedRobot, steps_per_rad: float, resolution: int, seed: int
) -> tuple[float, ...]:
    """Where each horn was mounted: the encoder reading at angle 0, drawn from ``seed`` so
    that the joint's range reads inside one turn (the middle of the turn when it cannot)."""
    draw = random.Random(f"{robot.name}:{seed}")
    zeros = []
    for joint in robot.description.joints:
        low, high = joint.position_limits if isinstance(joint, LimitedJoint) else (-3.0, 3.0)
        first = MARGIN_STEPS - low * steps_per_rad
        last = resolution - 1 - MARGIN_STEPS - high * steps_per_rad
        middle = (resolution - 1) / 2 - (low + high) / 2 * steps_per_rad
        zeros.append(round(draw.uniform(first, last)) if first < last else round(middle))
    return tuple(float(z) for z in zeros)


def _gripper_maps(robot: LoadedRobot) -> dict[int, tuple[float, float, str, tuple[float, float]]]:
    """Manifest slot of each gripper → (read offset, read weight, write mode, ctrl range)."""
    wiring = robot.tables.hal_wiring
    names = [joint.name for joint in robot.description.joints]
    maps = {}
    for g in wiring.grippers if wiring is not None else ():
        read = reading_map(g.read_mode, len(g.qpos_addrs), g.ctrl_range, g.qpos_scale)
        maps[names.index(g.joint)] = (read.offset, read.weights[0], g.write_mode, g.ctrl_range)
    return maps
