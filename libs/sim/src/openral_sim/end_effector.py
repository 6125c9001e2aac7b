"""The robot's tool centre point (TCP) in a native scene, and the one IK that moves it.

The TCP is the manifest's ``sim.tcp``: a body or a site of the model, an ``offset_m`` (between
the fingertips) and a ``quat_wxyz`` (the tool frame: z along the fingers). Its pose is
stated in the robot's base frame (the frame ``/tf`` calls the base: a mobile base's moving
frame, else the robot's root): position [m] and orientation as a unit quaternion (w, x, y,
z).

:meth:`EndEffector.joint_targets` turns a TCP pose into arm joint targets by differential
IK with mink on the scene's own model (the kinematics the robot really has there), solved
by daqp as one quadratic programme per control tick:

- a frame task on the TCP body (gain 1: the whole error in one control period; on an arm
  of fewer than six joints, which cannot hold every pose, the orientation weighs a tenth);
- the manifest's position limits of every arm joint (:class:`ArmPositionLimit`, the
  envelope of :class:`~openral_mujoco.command_limits.CommandLimits`) and its velocity
  limits (mink's ``VelocityLimit``) as inequalities;
- self-collision avoidance between the collision geoms of the body groups the manifest
  lists in ``sim.ik_collision_pairs``, kept at least ``sim.ik_collision_margin_m`` apart
  (:mod:`openral_sim.self_collision`);
- every other degree of freedom (grippers, a mobile base, the scene's objects) frozen.

A target out of reach is approached as far as those limits allow and no further: the
solution is the best step inside them, never a step past a limit.
"""

from __future__ import annotations

import mink
import mujoco
import numpy as np
from mink.limits.limit import Constraint
from openral_core.loaded import LoadedRobot
from openral_mujoco.command_limits import CommandLimits
from openral_mujoco.errors import HalError
from openral_mujoco.robot_addresses import RobotAddresses
from openral_mujoco.state import FloatArray

from openral_sim.self_collision import collision_limit

SOLVER = "daqp"
"""The QP solver of every IK step."""
_SPEED_SHARE = 0.8
"""Share of a joint's velocity limit the IK may plan for (the rest: the servo's headroom)."""
_FULL_POSE_JOINTS = 6
"""Arm joints it takes to place the TCP anywhere in any orientation."""
_FEW_JOINTS_TURN_COST = 0.1
"""Weight of the orientation error [1/rad] against the position error [1/m] for an arm with
fewer joints (a 5-joint arm cannot hold both; the position comes first)."""
_POSITION_GAIN = 0.95
"""Share of the distance to a position limit one step may close (mink's default)."""


class ArmPositionLimit(mink.Limit):
    """The manifest's position limits of the arm joints, as ``G dq <= h`` over every DOF."""

    def __init__(
        self, nv: int, qpos: list[int], dofs: list[int], low: FloatArray, high: FloatArray
    ) -> None:
        count = len(dofs)
        self.qpos, self.low, self.high = np.array(qpos, dtype=np.intp), low, high
        self.G = np.zeros((2 * count, nv))
        self.G[np.arange(count), dofs] = 1.0
        self.G[count + np.arange(count), dofs] = -1.0

    def compute_qp_inequalities(self, configuration: mink.Configuration, dt: float) -> Constraint:
        """Each arm joint may move at most :data:`_POSITION_GAIN` of the way to its limits."""
        del dt
        q = configuration.q[self.qpos]
        upper = np.maximum(self.high - q, 0.0) * _POSITION_GAIN
        lower = np.maximum(q - self.low, 0.0) * _POSITION_GAIN
        return Constraint(G=self.G, h=np.concatenate([upper, lower]))


class EndEffector:
    """The TCP of one robot in one native scene's model (see the module doc)."""

    def __init__(self, model: mujoco.MjModel, addresses: RobotAddresses, robot: LoadedRobot):
        """Find the TCP's body or site and set up the IK.

        Raises:
            HalError: The manifest declares no ``sim.tcp``, or the scene's model has no
                such body or site.
        """
        wiring = robot.tables.hal_wiring
        tcp = wiring.tcp if wiring is not None else None
        if tcp is None:
            raise HalError(
                f"{robot.name} has no tool centre point: end-effector actions need sim.tcp "
                "(a body or site, and an offset) in its manifest"
            )
        kind = mujoco.mjtObj.mjOBJ_SITE if tcp.kind == "site" else mujoco.mjtObj.mjOBJ_BODY
        self.kind, self.frame = tcp.kind, mujoco.mj_name2id(model, kind, tcp.frame)
        if self.frame < 0:
            raise HalError(f"the scene's model has no {tcp.kind} {tcp.frame!r} (sim.tcp)")
        self.offset = np.asarray(tcp.offset_m, dtype=np.float64)
        self.flange_quat = np.asarray(tcp.quat_wxyz, dtype=np.float64)
        turn = mink.SO3(self.flange_quat)
        self.flange = mink.SE3.from_rotation_and_translation(turn, self.offset)
        """The TCP's pose in the body's or site's frame."""
        self.arm = addresses.arm_slots
        self.configuration = mink.Configuration(model)
        turning = 1.0 if len(self.arm) >= _FULL_POSE_JOINTS else _FEW_JOINTS_TURN_COST
        self.task = mink.FrameTask(
            tcp.frame, tcp.kind, position_cost=1.0, orientation_cost=turning, gain=1.0
        )
        self._limits, self._frozen = self._constraints(model, addresses, robot)
        self._arm_qpos = addresses.qpos[self.arm]
        self.shortfall_m = 0.0
        """How far the last step's TCP ends from its target, to first order [m] (more than
        rounding: the limits stopped it short)."""

    def _constraints(
        self, model: mujoco.MjModel, addresses: RobotAddresses, robot: LoadedRobot
    ) -> tuple[list[mink.Limit], list[mink.DofFreezingTask]]:
        """The arm's position and velocity limits, and every other DOF frozen."""
        joints = [robot.description.joints[int(i)] for i in self.arm]
        wiring = robot.tables.hal_wiring
        envelope = CommandLimits(robot.description, wiring.grippers if wiring is not None else ())
        low, high = envelope.low[self.arm], envelope.high[self.arm]
        dofs = [int(d) for d in addresses.qvel[self.arm]]
        positions = ArmPositionLimit(model.nv, list(addresses.qpos[self.arm]), dofs, low, high)
        names = robot.tables.joint_name_map
        speeds = {names[j.name]: _SPEED_SHARE * j.velocity_limit for j in joints}
        arm_dofs = set(dofs)
        frozen = [d for d in range(model.nv) if d not in arm_dofs]
        freeze = [mink.DofFreezingTask(model, dof_indices=frozen)] if frozen else []
        limits: list[mink.Limit] = [positions, mink.VelocityLimit(model, speeds)]
        collisions = collision_limit(model, robot) if wiring is not None else None
        return limits + ([collisions] if collisions is not None else []), freeze

    def world_pose(self, data: mujoco.MjData) -> tuple[FloatArray, FloatArray]:
        """The TCP's world position [m] and orientation (w, x, y, z) as ``data`` holds them
        (MuJoCo's own quaternion routines: a few microseconds, it is in every observation)."""
        if self.kind == "site":
            position, frame = data.site_xpos[self.frame], np.empty(4)
            mujoco.mju_mat2Quat(frame, data.site_xmat[self.frame])
        else:
            position, frame = data.xpos[self.frame], data.xquat[self.frame]
        quat, offset = np.empty(4), np.empty(3)
        mujoco.mju_mulQuat(quat, frame, self.flange_quat)
        mujoco.mju_rotVecQuat(offset, self.offset, frame)
        return position + offset, quat

    def commanded_pose(self, data: mujoco.MjData, commanded: FloatArray) -> mink.SE3:
        """The TCP's world pose with the arm at its ``commanded`` targets (the rest of the
        state from ``data``)."""
        self._set(data, commanded)
        frame = self.configuration.get_transform_frame_to_world(self.task.frame_name, self.kind)
        return frame.multiply(self.flange)

    def _set(self, data: mujoco.MjData, commanded: FloatArray) -> None:
        q = np.array(data.qpos)
        q[self._arm_qpos] = commanded
        self.configuration.update(q)

    def joint_targets(
        self, data: mujoco.MjData, commanded: FloatArray, target_world: mink.SE3, dt: float
    ) -> FloatArray:
        """Arm joint targets (manifest order of the arm slots) one IK step from the arm's
        ``commanded`` targets (the rest of the state from ``data``) towards the TCP pose
        ``target_world``, over ``dt`` seconds.

        Stepping from the commanded targets, not the measured joints, keeps the servo's
        steady lag (gravity on a position servo) out of the IK's loop: the set points follow
        the TCP path exactly and the arm follows them with a constant lag.

        Raises:
            HalError: The solver found no step (it reports why).
        """
        self._set(data, commanded)
        self.task.set_target(target_world.multiply(self.flange.inverse()))
        try:
            velocity = mink.solve_ik(
                self.configuration,
                [self.task],
                dt,
                SOLVER,
                damping=1e-6,
                limits=self._limits,
                constraints=self._frozen,
            )
        except mink.MinkError as error:
            raise HalError(f"end-effector IK found no step: {error}") from error
        step = velocity * dt  # the task's residual after it, to first order: e + J dq
        residual = self.task.compute_error(self.configuration) + (
            self.task.compute_jacobian(self.configuration) @ step
        )
        self.shortfall_m = float(
            np.linalg.norm(residual[:3])
            + np.linalg.norm(residual[3:]) * np.linalg.norm(self.offset)
        )
        q = self.configuration.integrate(velocity, dt)
        return np.asarray(q[self._arm_qpos], dtype=np.float64)
