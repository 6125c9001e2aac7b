"""The robot's tool centre point (TCP) in a native scene, and the one IK that moves it.

The TCP is the manifest's ``sim.tcp``: a body or a site of the model, an ``offset_m`` (between
the fingertips) and a ``quat_wxyz`` (the tool frame: z along the fingers). Its pose is
stated in the robot's base frame (the frame ``/tf`` calls the base: a mobile base's moving
frame, else the robot's root): position [m] and orientation as a unit quaternion (w, x, y,
z).

:meth:`EndEffector.joint_targets` turns a TCP pose into arm joint targets by differential
IK on the scene's own model (the kinematics the robot really has there): mink gives the
frame task's error and Jacobian, and daqp solves one small quadratic programme per control
tick whose variables are the arm's joints alone (every other degree of freedom, grippers,
a mobile base, the scene's objects, stays where it is):

- least squares on the frame task's error (gain 1: the whole error in one control period;
  on an arm of fewer than six joints, which cannot hold every pose, the orientation weighs
  a tenth), damped in proportion to the squared error (Levenberg-Marquardt) so a far target
  out of reach is approached without chatter, and pulled towards the robot's start pose
  in the same proportion, so a far target does not fold the arm into a joint limit it
  cannot leave (at the target the pull is 0: it never offsets where the TCP ends);
- as bounds on each joint's step: the manifest's position limits (the envelope of
  :class:`~openral_mujoco.command_limits.CommandLimits`, a step closing at most 95 % of
  what is left) and its velocity limit (80 % of it, over the control period);
- self-collision avoidance between the collision geoms of the body groups the manifest
  lists in ``sim.ik_collision_pairs``, kept at least ``sim.ik_collision_margin_m`` apart
  (:mod:`openral_sim.self_collision`), one row per pair within reach.

Building the programme over the arm's joints, not every DOF of the scene with the others
frozen by equalities (mink's ``solve_ik``), gives the same step for a third of the cost.
A target out of reach is approached as far as those limits allow and no further: the
solution is the best step inside them, never a step past a limit.
"""

from __future__ import annotations

import daqp
import mink
import mujoco
import numpy as np
from openral_core.loaded import LoadedRobot
from openral_mujoco.command_limits import CommandLimits
from openral_mujoco.errors import HalError
from openral_mujoco.robot_addresses import RobotAddresses
from openral_mujoco.state import FloatArray

from openral_sim.scene_geometry import start_pose
from openral_sim.self_collision import collision_limit
from openral_sim.tcp_frame import TcpFrame

_HALVINGS = 5
"""Halvings of a step that would bring the robot's own links too close (then it holds)."""
_CLEARANCE_SLACK_M = 5e-4
"""How far [m] a step may end below the clearance it starts at (or the margin)."""
_DAMPING = 1e-6
"""Fixed damping of every IK step (on the arm's joints)."""
_LM_DAMPING = 0.1
"""Levenberg-Marquardt damping per squared weighted task error: a target far out of reach
(1 m: 0.1) gets a damped step and the arm comes to rest at the edge instead of alternating
between speed-capped steps either side of it; at a delta action's 1 cm it adds 1e-5."""
_POSTURE = 0.1
"""Weight of the pull towards the start pose per squared weighted task error, as the
damping above: far from its target (a jump, or a target out of reach) the arm keeps to a
posture like its start instead of straightening into a joint limit it cannot leave (a
local minimum: out of 9 far targets and back, the Panda stayed stuck 0.27 m short on 4
without it); near its target (1 cm steps: about 1e-5) the pull is too weak to bend the
path, and at the target it is 0."""
_POSTURE_GAIN = 0.2
"""Share of the way to the start pose that pull asks for in one step. Where the task has
no say (the arm's redundant swivel) the arm moves about half of this a step: 0.1 is too
little to leave the straightened elbow, 0.3 swivels a Panda holding a cube fast enough
to lose it (scripted_lift on 20 seeds: 18 lifted at 0.2, 13 at 0.3)."""
_INACTIVE = -1e30
"""daqp's "no lower bound" on a constraint row."""
_SPEED_SHARE = 0.8
"""Share of a joint's velocity limit the IK may plan for (the rest: the servo's headroom)."""
_FULL_POSE_JOINTS = 6
"""Arm joints it takes to place the TCP anywhere in any orientation."""
_FEW_JOINTS_TURN_COST = 0.1
"""Weight of the orientation error [1/rad] against the position error [1/m] for an arm with
fewer joints (a 5-joint arm cannot hold both; the position comes first)."""
_POSITION_GAIN = 0.95
"""Share of the distance to a position limit one step may close (mink's default)."""


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
        self.tcp = TcpFrame.locate(model, tcp)
        """The TCP's body or site and its offset there."""
        self.kind, self.frame, self.offset = self.tcp.kind, self.tcp.frame, self.tcp.offset
        self.flange_quat = np.asarray(tcp.quat_wxyz, dtype=np.float64)
        turn = mink.SO3(self.flange_quat)
        self.flange = mink.SE3.from_rotation_and_translation(turn, self.offset)
        """The TCP's pose in the body's or site's frame."""
        self._flange_inverse = self.flange.inverse()
        self.arm = addresses.arm_slots
        self.configuration = mink.Configuration(model)
        turning = 1.0 if len(self.arm) >= _FULL_POSE_JOINTS else _FEW_JOINTS_TURN_COST
        self.task = mink.FrameTask(
            tcp.frame, tcp.kind, position_cost=1.0, orientation_cost=turning, gain=1.0
        )
        self._dofs = np.asarray(addresses.qvel[self.arm], dtype=np.intp)
        self._arm_qpos = addresses.qpos[self.arm]
        self._low, self._high, self._speed = self._envelope(robot)
        self.rest = start_pose(model, robot.description, None).qpos[self._arm_qpos]
        """The arm's start pose [rad or m]: the posture the IK keeps to when far from its
        target (see ``_POSTURE``)."""
        self._collisions = collision_limit(model, robot) if wiring is not None else None
        self.shortfall_m = 0.0
        """How far the last step's TCP ends from its target, to first order [m] (more than
        rounding: the limits stopped it short)."""

    def _envelope(self, robot: LoadedRobot) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The arm's position limits [rad or m] (the envelope of
        :class:`~openral_mujoco.command_limits.CommandLimits`) and the speed [per s] the IK
        may plan for."""
        wiring = robot.tables.hal_wiring
        envelope = CommandLimits(robot.description, wiring.grippers if wiring is not None else ())
        joints = [robot.description.joints[int(i)] for i in self.arm]
        speed = np.array([_SPEED_SHARE * j.velocity_limit for j in joints], dtype=np.float64)
        return envelope.low[self.arm], envelope.high[self.arm], speed

    def frame_pose(self, data: mujoco.MjData) -> tuple[FloatArray, FloatArray]:
        """The world pose (position [m], quaternion w, x, y, z) of the body or site the TCP
        is fixed to, as ``data`` holds it (arrays of ``data``'s own for a body)."""
        if self.kind == "site":
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, data.site_xmat[self.frame])
            return data.site_xpos[self.frame], quat
        return data.xpos[self.frame], data.xquat[self.frame]

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
        self.task.set_target(target_world.multiply(self._flange_inverse))
        error = self.task.compute_error(self.configuration)
        jacobian = self.task.compute_jacobian(self.configuration)[:, self._dofs]
        step = self._keep_clear(data, commanded, self._solve(error, jacobian, commanded, dt))
        residual = error + jacobian @ step  # the task's residual after the step, to first order
        self.shortfall_m = float(
            np.linalg.norm(residual[:3])
            + np.linalg.norm(residual[3:]) * np.linalg.norm(self.offset)
        )
        return np.asarray(commanded + step, dtype=np.float64)  # one-DOF joints: q + Δq

    def _keep_clear(
        self, data: mujoco.MjData, commanded: FloatArray, step: FloatArray
    ) -> FloatArray:
        """``step``, halved while it would end the pairs closer than the margin and closer
        than they start (the QP bounds them to first order only; a turning hand can close a
        pair faster); no step at all if a sixteenth of it still would."""
        limit = self._collisions
        if limit is None or limit.clearance_m >= limit.reach_m:
            return step  # no pair within reach: nothing to check
        floor = min(limit.margin_m, limit.clearance_m) - _CLEARANCE_SLACK_M
        for _ in range(_HALVINGS):
            self._set(data, commanded + step)
            if limit.clearance(self.configuration.data) >= floor:
                break
            step = step / 2.0
        else:
            step = np.zeros_like(step)
        self._set(data, commanded)
        return step

    def _solve(
        self, error: FloatArray, jacobian: FloatArray, commanded: FloatArray, dt: float
    ) -> FloatArray:
        """The arm's joint step: least squares on the weighted task error, inside the
        position limits, the speed cap over ``dt`` and the self-collision rows.

        Raises:
            HalError: The solver found no step.
        """
        cost = self.task.cost
        weighted = cost[:, None] * jacobian
        hessian = weighted.T @ weighted
        weighted_error = cost * (self.task.gain * error)
        squared = float(weighted_error @ weighted_error)
        posture = _POSTURE * squared
        hessian.flat[:: len(self._dofs) + 1] += _DAMPING + _LM_DAMPING * squared + posture
        linear = weighted_error @ weighted + posture * _POSTURE_GAIN * (commanded - self.rest)
        reach = self._speed * dt
        upper = np.minimum(np.maximum(self._high - commanded, 0.0) * _POSITION_GAIN, reach)
        lower = np.maximum(-np.maximum(commanded - self._low, 0.0) * _POSITION_GAIN, -reach)
        rows, bounds = self._collision_rows()
        step, _, exitflag, _ = daqp.solve(
            hessian,
            linear,
            rows,
            np.concatenate([upper, bounds]),
            np.concatenate([lower, np.full(len(bounds), _INACTIVE)]),
            np.zeros(len(upper) + len(bounds), dtype=np.intc),
        )
        if exitflag <= 0:
            raise HalError(f"end-effector IK found no step (daqp exit flag {exitflag})")
        return np.asarray(step, dtype=np.float64)

    def _collision_rows(self) -> tuple[FloatArray, FloatArray]:
        """The self-collision inequalities on the arm's joints (pairs in reach only)."""
        if self._collisions is None:
            return np.zeros((0, len(self._dofs))), np.zeros(0)
        return self._collisions.rows(self.configuration.data, self._dofs)
