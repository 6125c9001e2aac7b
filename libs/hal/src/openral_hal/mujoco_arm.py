"""MujocoArmHAL: one data-driven MuJoCo HAL for every robot manifest (ADR-0023).

All robot-specific knowledge arrives as wiring: which qpos/qvel slot and actuator belong to
each canonical joint, how grippers are read and written, whether to reset to a keyframe or
seed the actuators, and which control law drives the joints. ``from_description`` derives
the wiring from a manifest with the same function that generates ``generated/…/tables``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from openral_core.models import RobotDescription
from openral_core.tables import GripperWiring, HalWiring, hal_wiring
from openral_mujoco.action import validated_action
from openral_mujoco.control_law import pd_torque, seed_position_servos
from openral_mujoco.gripper import gripper_ctrl, read_gripper
from openral_mujoco.mjcf_model import ctrl_limits
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import compile_robot_model, require_agreement
from openral_mujoco.state import FloatArray, JointStateSample

from openral_hal.errors import EStopLatched, HalError, NotConnected, SimulationDiverged

CONTROL_MODES = ("position", "torque_pd")
_BAD_STATE_WARNINGS = slice(
    int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADQACC) + 1
)
"""MuJoCo's NaN/Inf position, velocity and acceleration warnings (consecutive in mjtWarning)."""
SLEW_CHUNK_STEPS = 5
"""Physics steps per set-point update while a target is being approached."""


class MujocoArmHAL:
    """A robot simulated in its own MuJoCo model, driven by joint-space targets.

    The HAL owns the model: ``step()`` advances physics, ``send_action()`` only sets targets.
    """

    is_real = False
    """A simulation, never real hardware."""

    def __init__(
        self,
        *,
        mjcf_path: str | Path,
        joint_names: Sequence[str],
        joint_qpos_addr: Mapping[str, int],
        joint_qvel_addr: Mapping[str, int],
        actuator_index: Mapping[str, int],
        grippers: Sequence[GripperWiring] = (),
        floating_base: bool = False,
        keyframe_index: int | None = None,
        seed_ctrl_from_qpos: bool = False,
        settle_steps: int = 1,
        control_mode: str = "position",
        kp: Mapping[str, float] | None = None,
        kd: Mapping[str, float] | None = None,
        velocity_limit: Mapping[str, float] | None = None,
        gravity_enabled: bool = True,
        staleness_limit_s: float = 0.5,
    ) -> None:
        """Wire the HAL; nothing is loaded until :meth:`connect`.

        Args:
            mjcf_path: The MJCF file.
            joint_names: Canonical joint names in manifest order (the action/state order).
            joint_qpos_addr: Joint → index into ``data.qpos``.
            joint_qvel_addr: Joint → index into ``data.qvel``.
            actuator_index: Joint → actuator driving it.
            grippers: Gripper wiring; a gripper's joint is commanded and read per its modes.
            floating_base: The model's root is a free joint (informational; addresses above
                already include its offset).
            keyframe_index: Reset to this keyframe on connect.
            seed_ctrl_from_qpos: On connect, set every joint actuator's ctrl to its joint's
                current qpos so position servos hold the start pose.
            settle_steps: Physics steps run at the end of connect.
            control_mode: ``position`` (ctrl is a position target) or ``torque_pd`` (ctrl is
                torque; the HAL applies ``kp * (target - q) - kd * qdot`` every step).
            kp: Per-joint proportional gains for ``torque_pd``.
            kd: Per-joint derivative gains for ``torque_pd``.
            velocity_limit: Per-joint speed limit of the set point: a new target is
                approached no faster than this, as a real arm's controller interpolates
                (a joint without a limit jumps straight to its target).
            gravity_enabled: False zeroes the model's gravity.
            staleness_limit_s: A state sample is flagged stale when physics has not advanced
                for longer than this (wall time).
        """
        if control_mode not in CONTROL_MODES:
            raise HalError(f"control_mode {control_mode!r}; expected one of {CONTROL_MODES}")
        self.mjcf_path = Path(mjcf_path)
        self.joint_names = tuple(joint_names)
        self._qpos = np.array([joint_qpos_addr[n] for n in self.joint_names], dtype=np.intp)
        self._qvel = np.array([joint_qvel_addr[n] for n in self.joint_names], dtype=np.intp)
        self._act = np.array([actuator_index[n] for n in self.joint_names], dtype=np.intp)
        self.grippers = {g.joint: g for g in grippers}
        self._gripper_slots = {self.joint_names.index(j): g for j, g in self.grippers.items()}
        self._arm_slots = np.array(
            [i for i in range(len(self.joint_names)) if i not in self._gripper_slots],
            dtype=np.intp,
        )
        self._arm_qpos = self._qpos[self._arm_slots]
        self._arm_qvel = self._qvel[self._arm_slots]
        self._arm_act = self._act[self._arm_slots]
        self._ctrl_low = self._ctrl_high = self._arm_low = self._arm_high = np.zeros(0)
        self.floating_base = floating_base
        self.keyframe_index = keyframe_index
        self.seed_ctrl_from_qpos = seed_ctrl_from_qpos
        self.settle_steps = settle_steps
        self.control_mode = control_mode
        gains_kp, gains_kd = kp or {}, kd or {}
        arm = [self.joint_names[i] for i in self._arm_slots]
        self._kp = np.array([gains_kp.get(n, 0.0) for n in arm])
        self._kd = np.array([gains_kd.get(n, 0.0) for n in arm])
        limits = velocity_limit or {}
        self._vmax = np.array([limits.get(n, np.inf) for n in arm])
        self.gravity_enabled = gravity_enabled
        self.staleness_limit_s = staleness_limit_s
        self._model: mujoco.MjModel | None = None
        self._data: mujoco.MjData | None = None
        self._targets = np.zeros(len(self._arm_slots))
        self._setpoint = self._targets.copy()
        self._slewing = False
        self._reach: dict[int, FloatArray] = {}
        self._estopped = False
        self._last_step_ns = 0
        self.description: RobotDescription | None = None
        """The manifest this HAL was wired from (``from_description``); connect checks the
        model against it and reports a disagreement at the manifest's fields."""

    @classmethod
    def from_description(
        cls,
        description: RobotDescription,
        *,
        settle_steps: int | None = None,
        gravity_enabled: bool = True,
        staleness_limit_s: float = 0.5,
        manifest_dir: Path | None = None,
    ) -> MujocoArmHAL:
        """A HAL wired from ``description.sim``.

        Args:
            description: A validated manifest with a ``sim`` block.
            settle_steps: Overrides ``sim.settle_steps_default``.
            gravity_enabled: See :meth:`__init__`.
            staleness_limit_s: See :meth:`__init__`.
            manifest_dir: Folder of the manifest (for ``file:`` URIs); defaults to the
                folder of the file it was loaded from, else ``robots/<name>/``.
        """
        wiring = hal_wiring(description)
        if wiring is None:
            raise HalError(f"robot {description.name!r} has no sim block; cannot simulate it")
        path = robot_model_file(description, manifest_dir)
        kwargs = hal_kwargs(wiring)
        if settle_steps is not None:
            kwargs["settle_steps"] = settle_steps
        hal = cls(
            mjcf_path=path,
            gravity_enabled=gravity_enabled,
            staleness_limit_s=staleness_limit_s,
            **kwargs,
        )
        hal.description = description
        return hal

    # -- lifecycle -------------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        """True between :meth:`connect` and :meth:`disconnect`."""
        return self._model is not None

    def connect(self) -> None:
        """Load the model, reset (keyframe), seed the actuators, forward and settle."""
        if self.description is not None:
            model = compile_robot_model(self.description, self.mjcf_path)
            require_agreement(self.description, model)
        else:
            model = mujoco.MjModel.from_xml_path(str(self.mjcf_path))
        self._check_wiring(model)
        if not self.gravity_enabled:
            model.opt.gravity[:] = 0.0
        data = mujoco.MjData(model)
        if self.keyframe_index is not None:
            mujoco.mj_resetDataKeyframe(model, data, self.keyframe_index)
        if self.seed_ctrl_from_qpos:
            seed_position_servos(model, data)
        mujoco.mj_forward(model, data)
        self._reach = {
            n: self._vmax * n * model.opt.timestep for n in range(1, SLEW_CHUNK_STEPS + 1)
        }
        self._ctrl_low, self._ctrl_high = ctrl_limits(model)
        self._arm_low = self._ctrl_low[self._arm_act]
        self._arm_high = self._ctrl_high[self._arm_act]
        self._model, self._data = model, data
        self._hold_current_pose(data)
        self._estopped = False
        self.step(self.settle_steps)

    def disconnect(self) -> None:
        """Drop the model and data."""
        self._model = self._data = None

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """The live (model, data) pair."""
        return self._handles()

    # -- state and commands ----------------------------------------------------------------

    def read_state(self) -> JointStateSample:
        """Positions, velocities and efforts of every manifest joint."""
        _, data = self._handles()
        positions = data.qpos[self._qpos]
        for slot, gripper in self._gripper_slots.items():
            fingers = [data.qpos[a] for a in gripper.qpos_addrs]
            positions[slot] = read_gripper(
                gripper.read_mode, fingers, gripper.ctrl_range, gripper.qpos_scale
            )
        now = time.monotonic_ns()
        return JointStateSample(
            names=self.joint_names,
            positions=positions,
            velocities=data.qvel[self._qvel],
            efforts=data.actuator_force[self._act],
            stamp_ns=now,
            sim_time_s=float(data.time),
            stale=(now - self._last_step_ns) > self.staleness_limit_s * 1e9,
        )

    def send_action(self, action: object) -> None:
        """Set joint targets and gripper commands (one value per manifest joint).

        Raises:
            ActionRejected: Wrong type, width, or a non-finite value; nothing is changed.
            EStopLatched: The E-stop is latched.
        """
        _, data = self._handles()
        values = validated_action(action, self.joint_names)
        if self._estopped:
            raise EStopLatched("E-stop is latched; call release_estop() before sending actions")
        targets = values[self._arm_slots]
        if self.control_mode == "position":  # once here, so the set point never leaves it
            targets = np.minimum(np.maximum(targets, self._arm_low), self._arm_high)
        self._targets = targets
        self._slewing = True
        for slot, gripper in self._gripper_slots.items():
            ctrl = gripper_ctrl(gripper.write_mode, float(values[slot]), gripper.ctrl_range)
            self._set_ctrl(data, gripper.actuator_index, ctrl)
            if gripper.mirror_actuator_index is not None:
                self._set_ctrl(data, gripper.mirror_actuator_index, -ctrl)

    def step(self, n: int = 1) -> bool:
        """Advance physics ``n`` steps; returns False (and does nothing) while E-stopped.

        Raises:
            SimulationDiverged: MuJoCo met a NaN/Inf state and reset it.
        """
        model, data = self._handles()
        if self._estopped:
            return False
        bad_state = data.warning.number[_BAD_STATE_WARNINGS]  # a live view of the counters
        diverged_before = bad_state.tobytes()
        remaining = n
        while remaining > 0:
            chunk = min(remaining, SLEW_CHUNK_STEPS) if self._slewing else remaining
            if self._slewing:
                self._advance_setpoint(self._reach[chunk], data)
            if self.control_mode == "torque_pd":
                for _ in range(chunk):
                    self._apply_pd(data)
                    mujoco.mj_step(model, data)
            else:
                mujoco.mj_step(model, data, nstep=chunk)
            remaining -= chunk
        self._last_step_ns = time.monotonic_ns()
        if bad_state.tobytes() != diverged_before:
            raise SimulationDiverged(
                f"{self.mjcf_path.name}: the simulation diverged (NaN/Inf state) and MuJoCo "
                "reset it; lower the gains or the targets"
            )
        return True

    # -- E-stop ----------------------------------------------------------------------------

    @property
    def estopped(self) -> bool:
        """True while the E-stop is latched."""
        return self._estopped

    def estop(self) -> None:
        """Latch the E-stop: physics stops advancing and actions are refused."""
        self._estopped = True

    def release_estop(self) -> None:
        """Unlatch the E-stop; targets are reset to the current pose so nothing jumps."""
        _, data = self._handles()
        self._hold_current_pose(data)
        self._estopped = False

    # -- internals -------------------------------------------------------------------------

    def _handles(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        if self._model is None or self._data is None:
            raise NotConnected("the HAL is not connected; call connect() first")
        return self._model, self._data

    def _hold_current_pose(self, data: mujoco.MjData) -> None:
        self._targets = data.qpos[self._arm_qpos]
        self._setpoint = self._targets.copy()
        self._slewing = False

    def _advance_setpoint(self, reach: FloatArray, data: mujoco.MjData) -> None:
        """Move the set point towards the targets by at most ``reach`` per joint."""
        setpoint = self._setpoint
        setpoint = np.minimum(np.maximum(self._targets, setpoint - reach), setpoint + reach)
        self._setpoint = setpoint
        self._slewing = bool((setpoint != self._targets).any())
        if self.control_mode == "position":
            data.ctrl[self._arm_act] = setpoint

    def _apply_pd(self, data: mujoco.MjData) -> None:
        data.ctrl[self._arm_act] = pd_torque(
            self._kp,
            self._kd,
            self._setpoint,
            data.qpos[self._arm_qpos],
            data.qvel[self._arm_qvel],
            self._arm_low,
            self._arm_high,
        )

    def _set_ctrl(self, data: mujoco.MjData, actuator: int, value: float) -> None:
        """ctrl[actuator] = value clipped to the actuator's ctrlrange."""
        data.ctrl[actuator] = min(max(value, self._ctrl_low[actuator]), self._ctrl_high[actuator])

    def _check_wiring(self, model: mujoco.MjModel) -> None:
        problems = []
        for what, table, limit in (
            ("qpos address", self._qpos, model.nq),
            ("qvel address", self._qvel, model.nv),
            ("actuator index", self._act, model.nu),
        ):
            for name, value in zip(self.joint_names, table.tolist(), strict=True):
                if not 0 <= value < limit:
                    problems.append(f"{name}: {what} {value} outside 0..{limit - 1}")
        if self.keyframe_index is not None and not 0 <= self.keyframe_index < model.nkey:
            problems.append(f"keyframe_index {self.keyframe_index} but the model has {model.nkey}")
        if problems:
            raise HalError(
                f"{self.mjcf_path}: wiring does not fit the model ({'; '.join(problems)}); "
                "run `openral robot check` for a full report"
            )


def hal_kwargs(wiring: HalWiring) -> dict[str, Any]:
    """:class:`MujocoArmHAL` keyword arguments from a resolved wiring table.

    The generated ``tables/<id>.json`` files hold one under ``hal_wiring``
    (``HalWiring.from_dict`` reads it back).
    """
    kwargs = {f.name: getattr(wiring, f.name) for f in fields(wiring)}
    del kwargs["mjcf_uri"]
    kwargs["settle_steps"] = kwargs.pop("settle_steps_default")
    return kwargs
