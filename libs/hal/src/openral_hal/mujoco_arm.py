"""MujocoArmHAL: one data-driven MuJoCo HAL for every robot manifest (ADR-0023).

All robot-specific knowledge arrives with the loaded robot: its manifest (limits, grippers,
control law) and its tables (which qpos/qvel slot and actuator belong to each canonical
joint). The action contract itself — manifest units, clamping, slewing, grippers, the PD
law — is :class:`openral_mujoco.joint_driver.JointDriver`, which the native scenes use too.
"""

from __future__ import annotations

import time

import mujoco
from openral_core.loaded import LoadedRobot, loaded_robot
from openral_core.models import RobotDescription
from openral_core.tables import GripperWiring, HalWiring
from openral_mujoco.action import split_action
from openral_mujoco.errors import ActionRejected, SimulationDiverged
from openral_mujoco.joint_driver import JointDriver
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import compile_robot_model, require_agreement
from openral_mujoco.robot_addresses import locate_robot
from openral_mujoco.state import FloatArray, JointStateSample

from openral_hal.errors import HalError, NotConnected
from openral_hal.protocol import EStopLatch

CONTROL_PERIOD_S = 0.02
"""Control period of the robot alone under a control loop (50 Hz), rounded to whole
physics steps [s]."""


class MujocoArmHAL(EStopLatch):
    """A robot simulated in its own MuJoCo model, driven in manifest units.

    The HAL owns the model: ``step()`` advances physics, ``send_action()`` only sets targets.
    """

    is_real = False
    """A simulation, never real hardware."""

    def __init__(
        self,
        robot: LoadedRobot,
        *,
        settle_steps: int | None = None,
        gravity_enabled: bool = True,
        staleness_limit_s: float = 0.5,
    ) -> None:
        """Wire the HAL; nothing is loaded until :meth:`connect`.

        Args:
            robot: The loaded robot (manifest, folder, tables) with a ``sim`` block.
            settle_steps: Physics steps run at the end of connect (default: the manifest's
                ``sim.settle_steps_default``).
            gravity_enabled: False zeroes the model's gravity.
            staleness_limit_s: A state sample is flagged stale when physics has not advanced
                for longer than this [s, wall time].

        Raises:
            HalError: The robot has no ``sim`` block.
        """
        wiring = robot.tables.hal_wiring
        if wiring is None:
            raise HalError(f"robot {robot.name!r} has no sim block; cannot simulate it")
        self.robot = robot
        self.wiring: HalWiring = wiring
        self.mjcf_path = robot_model_file(robot.description, robot.folder)
        self.settle_steps = wiring.settle_steps_default if settle_steps is None else settle_steps
        self.gravity_enabled = gravity_enabled
        self.staleness_limit_s = staleness_limit_s
        self._model: mujoco.MjModel | None = None
        self._data: mujoco.MjData | None = None
        self._driver: JointDriver | None = None
        self._last_step_ns = 0

    @classmethod
    def from_robot(
        cls,
        robot: LoadedRobot,
        *,
        settle_steps: int | None = None,
        gravity_enabled: bool = True,
        staleness_limit_s: float = 0.5,
    ) -> MujocoArmHAL:
        """The HAL of a loaded robot (same as the constructor)."""
        return cls(
            robot,
            settle_steps=settle_steps,
            gravity_enabled=gravity_enabled,
            staleness_limit_s=staleness_limit_s,
        )

    @classmethod
    def from_description(
        cls,
        description: RobotDescription,
        *,
        settle_steps: int | None = None,
        gravity_enabled: bool = True,
        staleness_limit_s: float = 0.5,
    ) -> MujocoArmHAL:
        """A HAL for an already validated manifest (its folder and tables are looked up)."""
        return cls.from_robot(
            loaded_robot(description),
            settle_steps=settle_steps,
            gravity_enabled=gravity_enabled,
            staleness_limit_s=staleness_limit_s,
        )

    # -- what the HAL is -------------------------------------------------------------------

    @property
    def description(self) -> RobotDescription:
        """The manifest this HAL drives."""
        return self.robot.description

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Canonical joint names in manifest order."""
        return self.wiring.joint_names

    @property
    def action_names(self) -> tuple[str, ...]:
        """One action slot per manifest joint."""
        return self.wiring.joint_names

    @property
    def grippers(self) -> dict[str, GripperWiring]:
        """Gripper joint → its wiring."""
        return {g.joint: g for g in self.wiring.grippers}

    @property
    def driver(self) -> JointDriver:
        """The joint driver (clamp counters live in ``driver.limits.clamped``)."""
        return self._handles()[2]

    # -- lifecycle -------------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        """True between :meth:`connect` and :meth:`disconnect`."""
        return self._model is not None

    def connect(self) -> None:
        """Load and check the model (its gravity compensated if the manifest says so), reset
        (keyframe, then ``sim.start_pose``), hold that pose and settle.

        Raises:
            ManifestError: The model does not load, or contradicts the manifest (located).
            HalError: The wiring's addresses do not fit the model.
        """
        model = compile_robot_model(self.description, self.mjcf_path)
        require_agreement(self.description, model)
        try:
            addresses = locate_robot(self.wiring, model, model)
        except HalError as error:
            raise HalError(f"{self.mjcf_path}: wiring does not fit the model ({error})") from None
        if not self.gravity_enabled:
            model.opt.gravity[:] = 0.0
        data = mujoco.MjData(model)
        driver = JointDriver(self.description, self.wiring, model, addresses)
        driver.reset_to_keyframe(model, data)
        driver.start(model, data)
        self._model, self._data, self._driver = model, data, driver
        self._estopped = False
        self.step(self.settle_steps)

    def disconnect(self) -> None:
        """Drop the model and data."""
        self._model = self._data = self._driver = None

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """The live (model, data) pair."""
        model, data, _ = self._handles()
        return model, data

    # -- state and commands ----------------------------------------------------------------

    def read_state(self) -> JointStateSample:
        """Positions, velocities and efforts of every manifest joint, in manifest units."""
        _, data, driver = self._handles()
        positions, velocities, efforts = driver.read(data)
        now = time.monotonic_ns()
        stale = now - self._last_step_ns > self.staleness_limit_s * 1e9
        # (names, positions, velocities, efforts, stamp_ns, sim_time_s, stale)
        return JointStateSample(
            self.joint_names, positions, velocities, efforts, now, data.time, stale
        )

    def hold_action(self) -> FloatArray:
        """The action that keeps the robot where it is commanded now."""
        _, data, driver = self._handles()
        return driver.hold_action(data)

    def send_action(self, action: object) -> None:
        """Set joint targets and gripper commands: one value per manifest joint, or a typed
        :class:`~openral_mujoco.action.Action` (named slots, the gripper; no base here).

        Raises:
            ActionRejected: Wrong type, width, a non-finite value, or a base twist for this
                robot alone; nothing is changed.
            EStopLatched: The E-stop is latched.
        """
        _, data, driver = self._handles()
        joints, twist = split_action(
            action, self.action_names, self.hold_action, self.wiring.first_gripper
        )
        if twist is not None:
            raise ActionRejected("a base twist needs a mobile base in a scene, not the arm alone")
        self._refuse_when_estopped()
        driver.command(joints, data)

    @property
    def control_period_s(self) -> float:
        """:data:`CONTROL_PERIOD_S` rounded to whole physics steps (at least one) [s]."""
        return self._control_steps() * float(self.mujoco_handles()[0].opt.timestep)

    def tick(self, action: object | None, *, glide: bool = False) -> bool:
        """Apply ``action`` (None: keep the targets in force) and advance one control period;
        with ``glide`` the set point moves to it at constant speed over the period.

        Returns:
            True when physics advanced; False (nothing done) while E-stopped.

        Raises:
            ActionRejected: ``action`` is malformed; nothing is changed.
        """
        if self._estopped:
            return False
        if action is not None:
            _, data, driver = self._handles()
            driver.command(action, data, glide_s=self.control_period_s if glide else None)
        return self.step(self._control_steps())

    def reset(self) -> str:
        """Back to the keyframe and start pose, held and settled as :meth:`connect` leaves
        it; the E-stop latch is kept."""
        model, data, driver = self._handles()
        mujoco.mj_resetData(model, data)
        driver.reset_to_keyframe(model, data)
        driver.start(model, data)
        driver.advance(model, data, self.settle_steps)
        latch = "; the E-stop is still latched" if self._estopped else ""
        return f"{self.description.name}: start pose restored at t={data.time:.3f} s{latch}"

    def step(self, n: int = 1) -> bool:
        """Advance physics ``n`` steps; returns False (and does nothing) while E-stopped.

        Raises:
            SimulationDiverged: MuJoCo met a NaN/Inf state and reset it.
        """
        model, data, driver = self._handles()
        if self._estopped:
            return False
        try:
            driver.advance(model, data, n)
        except SimulationDiverged as error:
            raise SimulationDiverged(f"{self.mjcf_path.name}: {error}") from None
        finally:
            self._last_step_ns = time.monotonic_ns()
        return True

    # -- internals -------------------------------------------------------------------------

    def _on_release(self) -> None:
        """Targets ← the current pose, so nothing jumps when the E-stop is released."""
        _, data, driver = self._handles()
        driver.hold_current_pose(data)

    def _control_steps(self) -> int:
        timestep = float(self.mujoco_handles()[0].opt.timestep)
        return max(1, round(CONTROL_PERIOD_S / timestep))

    def _handles(self) -> tuple[mujoco.MjModel, mujoco.MjData, JointDriver]:
        if self._model is None or self._data is None or self._driver is None:
            raise NotConnected("the HAL is not connected; call connect() first")
        return self._model, self._data, self._driver
