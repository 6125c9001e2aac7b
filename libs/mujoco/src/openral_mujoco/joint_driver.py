"""The action contract, implemented once: one robot's joints in a MuJoCo model, driven and
read in manifest units.

An action is one value per manifest joint, in manifest order:

* an arm joint takes a position target [rad or m], clamped to its ``position_limits``
  (reported, see :mod:`openral_mujoco.command_limits`) and approached no faster than its
  ``velocity_limit`` (the set point is slewed, as a real arm's interpolator does); the
  set point is the actuator's ctrl: a position servo's target, or (``torque_pd``) the set
  point of the PD law compiled into the motor (``control_law.compile_pd_servos``), so
  MuJoCo applies either law at every physics step with no Python in the loop;
* a gripper joint takes the command of its ``write_mode``, mapped through ``ctrl_range`` to
  its actuator (and negated onto its mirror actuator).

A command may instead *glide* (``glide_s``): it is the next sample of a smooth path (a
joint trajectory sampled once per control period). Then the set point moves to the targets
at constant speed over ``glide_s`` seconds, and that speed is fed forward to the position
servos (``ctrl = set point + kv/kp · speed``, the velocity reference a joint servo tracks
with), so the joints follow the path instead of lagging it by ``kv/kp · speed``. A sample
that would need more than a joint's velocity limit is slewed as any other command.

A joint state reports every manifest joint in the same units: grippers through their
``read_mode`` (their velocities as the rate of that reading), efforts from the actuator
forces. :class:`MujocoArmHAL` (the robot alone) and
the native scene (the robot composed with props) both drive their robot with this class;
only the addresses differ (:mod:`openral_mujoco.robot_addresses`).
"""

from __future__ import annotations

from typing import NamedTuple

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import RobotDescription
from openral_core.tables import HalWiring

from openral_mujoco.action import validated_action
from openral_mujoco.command_limits import CommandLimits
from openral_mujoco.control_law import compile_pd_servos, seed_position_servos
from openral_mujoco.errors import SimulationDiverged
from openral_mujoco.gravity import require_gravity_compensation
from openral_mujoco.gripper import command_map, gripper_command, reading_map
from openral_mujoco.mjcf_model import ctrl_limits, is_position_servo
from openral_mujoco.robot_addresses import LocatedGripper, RobotAddresses
from openral_mujoco.start_pose import start_pose_addresses
from openral_mujoco.state import FloatArray

SLEW_CHUNK_STEPS = 5
"""Physics steps per set-point update while a target is being approached."""
UNLIMITED = 1e9
"""Speed of a joint without a velocity limit [rad/s or m/s]: finite, so the profile's
arithmetic stays finite, and fast enough to reach any target within one update."""
RAMP_S = 0.25
"""Time the set point takes to reach a joint's velocity limit from rest (and to stop) [s]."""
_BAD_STATE_WARNINGS = slice(
    int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADQACC) + 1
)
"""MuJoCo's NaN/Inf position, velocity and acceleration warnings (consecutive in mjtWarning)."""


class JointDriver:
    """Drives one robot's joints in one model, in manifest units (see the module doc)."""

    def __init__(
        self,
        robot: RobotDescription,
        wiring: HalWiring,
        model: mujoco.MjModel,
        addresses: RobotAddresses,
    ) -> None:
        """Wire the driver to ``model``, where the robot sits at ``addresses``."""
        self.names = wiring.joint_names
        self.wiring = wiring
        self.limits = CommandLimits(robot, wiring.grippers)
        self._at = addresses
        self._arm = addresses.arm_slots
        arm_names = [self.names[i] for i in self._arm]
        self._arm_qpos = addresses.qpos[self._arm]
        self._arm_act = addresses.actuator[self._arm]
        if wiring.gravity_compensation:
            require_gravity_compensation(model, addresses.qvel[self._arm])
        self._start_qpos, self._start_values = start_pose_addresses(wiring, addresses.qpos)
        if wiring.control_mode == "torque_pd":  # before the ctrl limits are read below
            kp = np.array([wiring.kp.get(n, 0.0) for n in arm_names])
            kd = np.array([wiring.kd.get(n, 0.0) for n in arm_names])
            compile_pd_servos(model, self._arm_act, kp, kd)
        self._vmax = np.array([wiring.velocity_limit.get(n, UNLIMITED) for n in arm_names])
        self._amax = self._vmax / RAMP_S
        self._two_a = 2.0 * self._amax
        self._dt = model.opt.timestep
        self._one_update = {  # within this of its target, a set point at rest lands on it
            n: np.minimum(self._amax * (n * self._dt) ** 2, self._vmax * n * self._dt)
            for n in range(1, SLEW_CHUNK_STEPS + 1)
        }
        self._ctrl_low, self._ctrl_high = ctrl_limits(model)
        self._arm_low = self._ctrl_low[self._arm_act]
        self._arm_high = self._ctrl_high[self._arm_act]
        self._limit_low = self.limits.low[self._arm]
        self._limit_high = self.limits.high[self._arm]
        self._command_low, self._command_high = self._command_bounds()
        self._writes = tuple(self._gripper_write(g) for g in addresses.grippers)
        self._reads = tuple(_gripper_read(g) for g in addresses.grippers)
        self._targets = np.zeros(len(self._arm))
        self._setpoint = self._targets.copy()
        self._speed = np.zeros(len(self._arm))
        self._moving = False  # any _speed nonzero
        self._slewing = False
        self._data_views: _Views | None = None
        self._in_force = b""  # the bytes of the last applied command
        self._in_force_clamped: tuple[int, ...] = ()  # its slots outside their limits
        self._feedforward = _velocity_gains(model, self._arm_act)
        self._glide_left_s = 0.0  # sim time until a gliding set point lands on its targets
        self._gliding = False  # the set point glided in the last period (speed fed forward)

    # -- start and hold --------------------------------------------------------------------

    def reset_to_keyframe(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Load the manifest's keyframe (if any) into ``data``, then its start pose over it
        (``sim.start_pose``, see :mod:`openral_mujoco.start_pose`)."""
        if self.wiring.keyframe_index is not None:
            mujoco.mj_resetDataKeyframe(model, data, self.wiring.keyframe_index)
        if self._start_qpos.size:
            data.qpos[self._start_qpos] = self._start_values

    def start(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Seed the servos (if the manifest says so), forward, and hold the pose now."""
        if self.wiring.seed_ctrl_from_qpos:
            seed_position_servos(model, data)
        mujoco.mj_forward(model, data)
        self.hold_current_pose(data)

    def hold_current_pose(self, data: mujoco.MjData) -> None:
        """Targets and set point ← the arm joints' positions now (nothing moves, nothing jumps)."""
        self._targets = data.qpos[self._arm_qpos].astype(np.float64)
        self._setpoint = self._targets.copy()
        self._speed = np.zeros(len(self._arm))
        self._moving = self._slewing = self._gliding = False
        self._glide_left_s = 0.0
        self._in_force = b""  # the next command applies in full, even a repeated one
        data.ctrl[self._arm_act] = np.clip(self._setpoint, self._arm_low, self._arm_high)

    def hold_action(self, data: mujoco.MjData) -> FloatArray:
        """The action that keeps the robot where it is commanded now: the arm targets, and
        each gripper's command that gives its actuator's present control."""
        action = np.empty(len(self.names))
        action[self._arm] = self._targets
        for g in self._at.grippers:
            ctrl = float(data.ctrl[g.actuator])
            action[g.slot] = gripper_command(g.wiring.write_mode, ctrl, g.wiring.ctrl_range)
        return action

    # -- command, advance, read ------------------------------------------------------------

    def command(self, action: object, data: mujoco.MjData, *, glide_s: float | None = None) -> None:
        """Validate, clamp and apply one action (see the module doc); with ``glide_s`` [s]
        the set point glides to it over that long.

        Raises:
            ActionRejected: Wrong type, width, or a non-finite value; nothing is changed.
        """
        values = validated_action(action, self.names, finite_checked_by_caller=True)
        raw = values.tobytes()
        if raw == self._in_force:  # the command in force again: only its clamps count again
            if self._in_force_clamped:
                self.limits.report(self._in_force_clamped, values)
            return
        bounded = np.fmin(np.fmax(values, self._command_low), self._command_high)
        clamped: tuple[int, ...] = ()
        if bounded.tobytes() != raw:  # one pass decides; the rest is rare
            validated_action(values, self.names)  # NaN/Inf never pass fmin/fmax unchanged
            clamped = self.limits.outside(values)
            self.limits.report(clamped, values)
        self._in_force, self._in_force_clamped = raw, clamped
        targets = bounded[self._arm]
        self._targets = targets  # a set point at rest on its targets has nothing to do:
        self._slewing = self._moving or targets.tobytes() != self._setpoint.tobytes()
        self._glide_left_s, self._gliding = 0.0, False  # a slew goes on from the speed
        if glide_s is not None and glide_s > 0.0:
            speed = (targets - self._setpoint) / glide_s
            if (np.abs(speed) <= self._vmax).all():  # never faster than the manifest allows
                self._speed, self._glide_left_s, self._slewing = speed, glide_s, False
        if self._writes:
            ctrl, commands = data.ctrl, bounded.tolist()
            for slot, actuator, offset, scale, low, high, mirror in self._writes:
                value = _clip(offset + scale * commands[slot], low, high)
                ctrl[actuator] = value
                if mirror is not None:
                    ctrl[mirror[0]] = _clip(-value, mirror[1], mirror[2])

    def advance(self, model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> None:
        """Advance physics ``steps`` steps, slewing the set point and applying the law.

        Raises:
            SimulationDiverged: MuJoCo met a NaN/Inf state and reset it.
        """
        bad_state = self._views(data).bad_state
        diverged_before = bad_state.tobytes()
        if self._glide_left_s > 0.0:
            steps = self._glide(model, data, steps)
        elif self._gliding:  # a glide landed and no sample followed it: the set point stops
            self._stop_glide(data)
        if self._slewing:
            self._slew(model, data, steps)
        else:
            mujoco.mj_step(model, data, nstep=steps)
        if bad_state.tobytes() != diverged_before:
            raise SimulationDiverged(
                "the simulation diverged (NaN/Inf state) and MuJoCo reset it; lower the "
                "gains or the targets"
            )

    def read(self, data: mujoco.MjData) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(positions, velocities, efforts) of every manifest joint, in manifest units."""
        _, qpos, qvel, force, _ = self._views(data)
        positions = qpos[self._at.qpos]  # fancy indexing copies: safe to write into
        velocities = qvel[self._at.qvel]
        for slot, fingers, finger_dofs, weights, offset in self._reads:
            position, rate = offset, 0.0
            for q, v, w in zip(fingers, finger_dofs, weights, strict=True):
                position += w * qpos.item(q)
                rate += w * qvel.item(v)
            positions[slot] = position
            velocities[slot] = rate
        return positions, velocities, force[self._at.actuator]

    @property
    def addresses(self) -> RobotAddresses:
        """Where the robot's joints, fingers and actuators are in the driver's model."""
        return self._at

    @property
    def setpoint(self) -> FloatArray:
        """The arm joints' present set point (a copy), in arm-slot order."""
        return self._setpoint.copy()

    # -- internals -------------------------------------------------------------------------

    def _advance_setpoint(self, chunk: int, data: mujoco.MjData) -> None:
        """Move the set point ``chunk`` physics steps towards the targets (see
        :meth:`_profile`) and hand it to the position servos."""
        error = self._targets - self._setpoint
        if not self._moving and (np.abs(error) <= self._one_update[chunk]).all():
            # From rest, the profile would land every joint on its target in this update
            # (a holding loop's case); neither array is ever changed in place.
            self._setpoint = self._targets
            self._slewing = False
        else:
            self._profile(error, chunk * self._dt)
        data.ctrl[self._arm_act] = self._setpoint

    def _profile(self, error: FloatArray, dt: float) -> None:
        """Move the set point ``dt`` seconds towards the targets: speed at most the velocity
        limit, changed by at most the limit per :data:`RAMP_S` (a trapezoidal profile that
        brakes in time to stop on the target). A set point that would pass its target stops
        on it, and one that brakes after a reversed target stops on the joint's limit: it
        never leaves the manifest's limits (unless it started outside them)."""
        setpoint, targets = self._setpoint, self._targets
        wanted = np.copysign(np.minimum(self._vmax, np.sqrt(self._two_a * np.abs(error))), error)
        step = self._amax * dt
        speed = np.minimum(np.maximum(wanted, self._speed - step), self._speed + step)
        moved = setpoint + speed * dt
        arrived = (targets - moved) * error <= 0.0  # never past the target
        if arrived.any():
            moved[arrived] = targets[arrived]
            speed[arrived] = 0.0
        low = np.minimum(self._limit_low, setpoint)  # a start outside may move in
        high = np.maximum(self._limit_high, setpoint)
        inside = np.minimum(np.maximum(moved, low), high)  # a reversal never overshoots
        self._setpoint = inside
        self._speed = np.where(inside != moved, 0.0, speed)
        self._moving = bool(self._speed.any())
        self._slewing = bool((inside != targets).any())

    def _views(self, data: mujoco.MjData) -> _Views:
        """Live views of ``data``'s arrays, made once per data (each attribute access of
        the bindings builds a new array object)."""
        views = self._data_views
        if views is None or views.data is not data:
            bad_state = data.warning.number[_BAD_STATE_WARNINGS]
            views = _Views(data, data.qpos, data.qvel, data.actuator_force, bad_state)
            self._data_views = views
        return views

    def _slew(self, model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> None:
        """``steps`` physics steps, the set point updated every :data:`SLEW_CHUNK_STEPS`
        until it rests on the targets."""
        remaining = steps
        while remaining > 0 and self._slewing:
            chunk = min(remaining, SLEW_CHUNK_STEPS)
            self._advance_setpoint(chunk, data)
            mujoco.mj_step(model, data, nstep=chunk)
            remaining -= chunk
        if remaining > 0:
            mujoco.mj_step(model, data, nstep=remaining)

    def _glide(self, model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> int:
        """Physics steps of a glide (see the module doc), the set point and its fed-forward
        speed updated every :data:`SLEW_CHUNK_STEPS`; returns the steps left after it ended."""
        ctrl, act = data.ctrl, self._arm_act
        while steps > 0 and self._glide_left_s > 0.0:
            chunk = min(steps, SLEW_CHUNK_STEPS)
            dt = chunk * self._dt
            if dt >= self._glide_left_s - 1e-12:  # lands on the targets, still moving
                self._setpoint, self._glide_left_s = self._targets, 0.0
            else:
                self._setpoint = self._setpoint + self._speed * dt
                self._glide_left_s -= dt
            ctrl[act] = self._setpoint + self._feedforward * self._speed
            mujoco.mj_step(model, data, nstep=chunk)
            steps -= chunk
        self._moving = self._gliding = bool(self._speed.any())
        return steps

    def _stop_glide(self, data: mujoco.MjData) -> None:
        """The set point rests where its glide landed: no speed, no feed-forward."""
        self._speed = np.zeros(len(self._arm))
        self._moving = self._gliding = False
        data.ctrl[self._arm_act] = self._setpoint

    def _command_bounds(self) -> tuple[FloatArray, FloatArray]:
        """Per slot, the range a command is clamped to in one pass: the manifest's limits
        (:class:`CommandLimits`, unlimited as the largest finite float), narrowed to the
        servo's ctrlrange (a compiled PD law has none), so the set point never leaves what
        the servo accepts."""
        largest = np.finfo(np.float64).max  # finite, so an infinite command always changes
        low = np.maximum(self.limits.low, -largest)
        high = np.minimum(self.limits.high, largest)
        low[self._arm] = np.maximum(low[self._arm], self._arm_low)
        high[self._arm] = np.minimum(high[self._arm], self._arm_high)
        return low, high

    def _gripper_write(self, g: LocatedGripper) -> _Write:
        """One gripper's precomputed command path (see :func:`command_map`)."""
        forward = command_map(g.wiring.write_mode, g.wiring.ctrl_range)
        a = g.actuator
        mirror = (
            None
            if g.mirror_actuator is None
            else (
                g.mirror_actuator,
                float(self._ctrl_low[g.mirror_actuator]),
                float(self._ctrl_high[g.mirror_actuator]),
            )
        )
        low, high = float(self._ctrl_low[a]), float(self._ctrl_high[a])
        return (g.slot, a, forward.offset, forward.weights[0], low, high, mirror)


class _Views(NamedTuple):
    data: mujoco.MjData
    qpos: FloatArray
    qvel: FloatArray
    actuator_force: FloatArray
    bad_state: npt.NDArray[np.int32]
    """MuJoCo's NaN/Inf position, velocity and acceleration warning counters."""


_Write = tuple[int, int, float, float, float, float, tuple[int, float, float] | None]
"""(slot, actuator, offset, scale, ctrl low, ctrl high, (mirror, low, high) or None)."""
_Read = tuple[int, list[int], list[int], tuple[float, ...], float]
"""(slot, finger qpos addresses, finger dof addresses, weights, offset)."""


def _gripper_read(g: LocatedGripper) -> _Read:
    """One gripper's precomputed reading (see :func:`reading_map`)."""
    w = g.wiring
    reading = reading_map(w.read_mode, len(g.finger_qpos), w.ctrl_range, w.qpos_scale)
    return (g.slot, g.finger_qpos.tolist(), g.finger_qvel.tolist(), reading.weights, reading.offset)


def _velocity_gains(model: mujoco.MjModel, actuators: npt.NDArray[np.intp]) -> FloatArray:
    """Per actuator, kv/kp of an affine position servo (``kp·(ctrl - q) - kv·q̇``: bias
    ``[0, -kp, -kv]``), the set-point offset that makes it track a speed; 0 for any other."""
    bias = model.actuator_biasprm[actuators]
    affine = np.array([is_position_servo(model, int(a)) for a in actuators], dtype=bool)
    usable = affine & (bias[:, 1] < 0.0)
    return np.where(usable, bias[:, 2] / np.where(usable, bias[:, 1], -1.0), 0.0)


def _clip(value: float, low: float, high: float) -> float:
    return low if value < low else high if value > high else value
