"""The velocity drive and the odometry of a robot's holonomic mobile base in a native scene.

A command is a velocity in the base frame: ``vx`` forward and ``vy`` to the left [m/s] and
``wz`` counter-clockwise about the vertical [rad/s] (a ``geometry_msgs/Twist`` on
``cmd_vel``). The drive

* clamps it to the manifest's limits: a planar speed above ``max_linear_velocity_m_s`` is
  scaled down keeping its direction, ``wz`` is clamped to ``max_angular_velocity_rad_s``;
* ramps the velocity in force towards it by at most ``max_linear_acceleration_m_s2`` and
  ``max_angular_acceleration_rad_s2``, every :data:`BASE_UPDATE_STEPS` physics steps;
* turns it into the drive joints' velocities: the x and y slides move in the frame the base
  was placed in, so the base-frame velocity is rotated by the base's heading (joint velocity
  = R(yaw)·v), and written to the velocity actuators with a feed-forward (below);
* after ``command_timeout_s`` of simulated time without a command, ramps down to a stop;
  :meth:`BaseDrive.halt` (an E-stop) stops commanding at once: every actuator's ctrl is 0.

Feed-forward: a velocity actuator pushes kv·(ctrl - q̇). robosuite's Omron base gives its
joints 250 N of dry friction against kv = 1000 on a 239 kg robot, so ctrl = v alone would
settle 0.25 m/s below v (0.05 m/s for 0.3 commanded) and lag a ramp by m/kv = 0.24 s. Like a
wheel controller's feed-forward, the drive adds (friction·sign(q̇*) + M·q̈* + c)/kv, where q̇*
and q̈* are the joint velocity and acceleration it asks for, the friction, gain and the
joint-space inertia M (diagonal) are read from the compiled model and c is the simulation's
bias force (the centrifugal pull of the arm turning about the yaw axis); ctrl stays inside
the actuator's ctrlrange.

Odometry comes from the simulation: the base frame's pose in the odometry frame (where the
base frame was at the last reset, REP 105) and its twist in the base frame, computed from
the drive joints' qpos and qvel (:class:`~openral_mujoco.mobile_base.DriveGeometry`), so it
is exact and current after every step.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np
from openral_core.tables import MobileBaseWiring
from openral_mujoco.errors import ActionRejected
from openral_mujoco.joint_driver import SLEW_CHUNK_STEPS
from openral_mujoco.mobile_base import DriveGeometry, drive_geometry
from openral_mujoco.state import FloatArray, JointStateSample

BASE_UPDATE_STEPS = SLEW_CHUNK_STEPS
"""Physics steps between two updates of the base's actuators (10 ms on a 2 ms step): the
joint driver's slew chunk, so the arm moves exactly as without a base."""
FRICTION_RAMP = 0.01
"""Joint speed [m/s or rad/s] over which the friction feed-forward grows to its full value,
so a joint velocity passing through zero (a turning base) does not flip it at once."""


@dataclass(frozen=True)
class BaseCommand:
    """A velocity command as the drive took it: base frame, clamped to the limits."""

    vx_m_s: float
    vy_m_s: float
    wz_rad_s: float
    clamped: bool
    """True when the command asked for more than the manifest's limits."""


@dataclass(frozen=True)
class BaseOdometry:
    """The base frame's pose in the odometry frame and its twist in the base frame."""

    x_m: float
    y_m: float
    yaw_rad: float
    """Heading in the odometry frame, in (-pi, pi] [rad]."""
    vx_m_s: float
    vy_m_s: float
    wz_rad_s: float
    sim_time_s: float
    """Simulated time of the reading [s]."""
    odom_frame: str
    base_frame: str


class BaseDrive:
    """Drives one holonomic base in a scene's model and reads its odometry (see the module
    doc). The scene calls :meth:`update` before every :data:`BASE_UPDATE_STEPS` physics steps."""

    def __init__(self, wiring: MobileBaseWiring, model: mujoco.MjModel, data: mujoco.MjData):
        """Find the drive of ``wiring`` in ``model`` (checked by ``robot check`` before)."""
        self.wiring = wiring
        self.geometry: DriveGeometry = drive_geometry(model, wiring)
        self._model, self._data = model, data
        dof = self.geometry.dof  # the diagonal of M: the last entry of each row of its CSR
        self._mass_adr = np.array(model.M_rowadr[dof] + model.M_rownnz[dof] - 1, dtype=np.intp)
        self._target = np.zeros(3)
        self._velocity = np.zeros(3)
        self._joint_velocity = np.zeros(3)
        self._last_command_s = -math.inf
        self._origin, self._origin_heading = self.geometry.pose(data.qpos)

    # -- commands --------------------------------------------------------------------------

    def command(
        self, vx_m_s: float, vy_m_s: float, wz_rad_s: float, now_s: float | None = None
    ) -> BaseCommand:
        """Set the velocity to drive at (base frame), clamped to the limits.

        Args:
            vx_m_s: Forward velocity [m/s].
            vy_m_s: Leftward velocity [m/s].
            wz_rad_s: Turn rate, counter-clockwise seen from above [rad/s].
            now_s: Simulated time of the command [s] (default: the scene's time now); the
                timeout counts from it.

        Raises:
            ActionRejected: A value that is not a finite number; nothing is changed.
        """
        values = (vx_m_s, vy_m_s, wz_rad_s)
        for name, value in zip(("vx_m_s", "vy_m_s", "wz_rad_s"), values, strict=True):
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ActionRejected(f"base command {name}={value!r} is not a number")
            if not math.isfinite(value):
                raise ActionRejected(f"base command {name}={value!r} is not finite")
        limits = self.wiring
        vx, vy, wz = (float(v) for v in values)
        speed = math.hypot(vx, vy)
        scale = min(1.0, limits.max_linear_velocity_m_s / speed) if speed > 0 else 1.0
        turn = max(-limits.max_angular_velocity_rad_s, min(limits.max_angular_velocity_rad_s, wz))
        self._target = np.array([vx * scale, vy * scale, turn])
        self._last_command_s = float(self._data.time) if now_s is None else float(now_s)
        clamped = scale < 1.0 or turn != wz
        return BaseCommand(vx * scale, vy * scale, turn, clamped)

    def halt(self) -> None:
        """Stop at once (an E-stop): command, ramp and every drive ctrl to zero, and the
        drive joints' velocities too (the base brakes to a standstill; its odometry says
        so)."""
        self._target = np.zeros(3)
        self._velocity = np.zeros(3)
        self._joint_velocity = np.zeros(3)
        self._last_command_s = -math.inf
        self._data.ctrl[self.geometry.actuator] = 0.0
        self._data.qvel[self.geometry.dof] = 0.0

    def reset(self) -> None:
        """After the scene's reset: halted, and the odometry frame is the base frame now."""
        self.halt()
        self._origin, self._origin_heading = self.geometry.pose(self._data.qpos)

    @property
    def origin(self) -> tuple[float, float, float]:
        """The odometry frame in the world: where the base frame was at the last reset, (x, y)
        [m] and heading [rad]."""
        x, y = (float(v) for v in self._origin)
        return x, y, float(self._origin_heading)

    @property
    def root_in_base_frame(self) -> tuple[float, float, float]:
        """Where the base's root body (``NativeScene.base_frame``, the frame depth clouds are
        given in) sits in the base frame (x, y, z) [m]: a static transform from
        ``wiring.base_frame`` to it (its axes are the base frame's)."""
        x, y, z = self.geometry.root_offset.tolist()
        return x, y, z

    @property
    def command_in_force(self) -> tuple[float, float, float]:
        """The (vx, vy, wz) the drive ramps towards: the last command, zero after the
        timeout or a halt."""
        vx, vy, wz = self._target.tolist()
        return vx, vy, wz

    @property
    def velocity_in_force(self) -> tuple[float, float, float]:
        """The ramped (vx, vy, wz) the actuators were last given [m/s, rad/s]."""
        vx, vy, wz = self._velocity.tolist()
        return vx, vy, wz

    # -- the scene's update ----------------------------------------------------------------

    def update(self, dt_s: float) -> None:
        """Ramp towards the command for the next ``dt_s`` seconds and write the actuators'
        ctrl (call before stepping the physics for ``dt_s``)."""
        if self._data.time - self._last_command_s >= self.wiring.command_timeout_s:
            self._target = np.zeros(3)
        self._velocity = self._ramped(dt_s)
        geometry = self.geometry
        _, heading = geometry.pose(self._data.qpos)
        c, s = math.cos(heading), math.sin(heading)
        vx, vy, wz = self._velocity.tolist()
        world = np.array([c * vx - s * vy, s * vx + c * vy])
        joint = np.array([*(geometry.to_slides @ world), geometry.yaw_sign * wz])
        acceleration = (joint - self._joint_velocity) / dt_s
        self._joint_velocity = joint
        inertia = self._data.M[self._mass_adr]
        friction = geometry.friction * np.clip(joint / FRICTION_RAMP, -1.0, 1.0)
        bias = self._data.qfrc_bias[geometry.dof]  # centrifugal: the arm swung round the axis
        ctrl = joint + (friction + inertia * acceleration + bias) / geometry.kv
        self._data.ctrl[geometry.actuator] = np.clip(ctrl, geometry.ctrl_low, geometry.ctrl_high)

    def _ramped(self, dt_s: float) -> FloatArray:
        """The velocity in force moved towards the command by at most the acceleration
        limits over ``dt_s`` (the planar part as one vector, keeping its direction)."""
        change = self._target - self._velocity
        planar = math.hypot(change[0], change[1])
        most = self.wiring.max_linear_acceleration_m_s2 * dt_s
        if planar > most:
            change[:2] *= most / planar
        turn = self.wiring.max_angular_acceleration_rad_s2 * dt_s
        change[2] = max(-turn, min(turn, change[2]))
        ramped: FloatArray = self._velocity + change
        return ramped

    # -- odometry --------------------------------------------------------------------------

    def odometry(self) -> BaseOdometry:
        """The base frame's pose in the odometry frame and its twist in the base frame, as
        the scene's data holds them now."""
        geometry, data = self.geometry, self._data
        position, heading = geometry.pose(data.qpos)
        moved = position - self._origin
        c0, s0 = math.cos(self._origin_heading), math.sin(self._origin_heading)
        velocity, turn = geometry.world_twist(data.qvel)
        c, s = math.cos(heading), math.sin(heading)
        yaw = heading - self._origin_heading
        return BaseOdometry(
            x_m=float(c0 * moved[0] + s0 * moved[1]),
            y_m=float(-s0 * moved[0] + c0 * moved[1]),
            yaw_rad=math.atan2(math.sin(yaw), math.cos(yaw)),
            vx_m_s=float(c * velocity[0] + s * velocity[1]),
            vy_m_s=float(-s * velocity[0] + c * velocity[1]),
            wz_rad_s=turn,
            sim_time_s=float(data.time),
            odom_frame=self.wiring.odom_frame,
            base_frame=self.wiring.base_frame,
        )

    def joint_state(self) -> JointStateSample:
        """The drive joints (x, y, yaw, by their MJCF names) as the scene's data holds them
        now: positions [m, m, rad], velocities [m/s, m/s, rad/s] and actuator forces [N,
        N, N·m], for ``/joint_states`` beside the manifest's joints."""
        geometry, data = self.geometry, self._data
        return JointStateSample(
            names=self.wiring.joints,
            positions=data.qpos[geometry.qpos].copy(),
            velocities=data.qvel[geometry.dof].copy(),
            efforts=data.qfrc_actuator[geometry.dof].copy(),
            stamp_ns=time.monotonic_ns(),
            sim_time_s=float(data.time),
        )
