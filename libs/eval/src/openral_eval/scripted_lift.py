"""``scripted_lift``: a privileged scripted policy that lifts a cube from above.

It reads the simulation (:class:`~openral_eval.privileged.Privileged`): the cube's pose and
the robot's first gripper as its manifest declares it (``sim.grippers[0]``: its action
slot, ``tcp_body`` and ``tcp_offset_m``), so nothing of any one robot is written here. It
then moves the gripper's tool centre point through four phases:

1. ``approach``: ``approach_m`` above the cube, fingers pointing down and turned to the
   cube's nearest face;
2. ``descend``: to the cube's centre;
3. ``close``: the gripper closes for ``close_s``;
4. ``lift``: ``lift_m`` above where the cube started.

Each step it turns the Cartesian error into joint targets by damped least squares on the
point's Jacobian: speed at most ``speed_m_s``, turn rate at most 1.5 rad/s. The targets
are integrated onto the previous command, so gravity's sag does not become a lasting
error. It uses no randomness and no wall clock: the same episode gives the same actions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from openral_mujoco.state import FloatArray

from openral_eval.policy import Observation, PolicyConfigError
from openral_eval.privileged import Privileged, PrivilegedGripper

PHASES = ("approach", "descend", "close", "lift")
DAMPING = 0.05
"""Damped-least-squares damping [m] (keeps steps small near singularities)."""
TURN_RATE = 1.5
"""Largest commanded turn rate [rad/s]."""
REACHED_M = 0.008
"""A phase's target counts as reached within this distance [m]."""


@dataclass(frozen=True)
class LiftConfig:
    """Parameters of :class:`ScriptedLift` (``-p key=value``)."""

    object: str = "red_cube"
    """The scene object to lift."""
    approach_m: float = 0.10
    lift_m: float = 0.12
    speed_m_s: float = 0.35
    close_s: float = 0.6
    gain: float = 6.0
    """Proportional gain of the Cartesian error [1/s]."""

    def __post_init__(self) -> None:
        if self.speed_m_s <= 0 or self.gain <= 0 or self.close_s < 0:
            raise PolicyConfigError("scripted_lift speed_m_s and gain must be > 0, close_s >= 0")


class ScriptedLift:
    """The four-phase lift of the module doc; one instance per episode."""

    config_type = LiftConfig
    """Its parameters (``--param key=value``)."""

    needs_privileged = True
    """It reads the simulation (only an evaluation episode on a native scene gives it)."""
    required_slots: tuple[str, ...] = ()

    def __init__(self, config: LiftConfig) -> None:
        self.config = config
        self.phase = PHASES[0]
        self._command: FloatArray | None = None
        self._closing_s = 0.0
        self._start: FloatArray | None = None
        self._period_s = 0.05
        self._last_time_s: float | None = None

    def act(self, obs: Observation) -> FloatArray:
        """The next action: arm joint targets from the IK step, and the gripper command."""
        world = obs.get("privileged")
        if world is None:
            raise PolicyConfigError("scripted_lift needs privileged state (episodes only)")
        _, hold = obs["action_spec"]
        if self._command is None:
            self._command = np.asarray(hold, dtype=np.float64).copy()
        now = float(obs["time_s"])
        if self._last_time_s is not None and now > self._last_time_s:
            self._period_s = now - self._last_time_s  # the control period
        self._last_time_s = now
        gripper = _gripper(world)
        if self.config.object not in world.objects:
            have = ", ".join(sorted(world.objects)) or "none"
            raise PolicyConfigError(f"no scene object {self.config.object!r}; objects: {have}")
        position, quat = world.objects[self.config.object]
        if self._start is None:
            self._start = np.array(position, dtype=np.float64)
        hand = _tcp(world, gripper)  # the kinematics of this step, computed once
        target, closing = self._phase_target(np.asarray(position), hand[0])
        self._command[list(world.arm_slots)] += self._ik_step(world, hand, target, np.asarray(quat))
        self._command[gripper.slot] = closing
        return self._command.copy()

    # -- phases ----------------------------------------------------------------------------

    def _phase_target(self, cube: FloatArray, tcp: FloatArray) -> tuple[FloatArray, float]:
        """Where the gripper's centre (now at ``tcp``) should go, and the gripper command."""
        config = self.config
        above = cube + np.array([0.0, 0.0, config.approach_m])
        if self.phase == "approach":
            if np.linalg.norm(tcp - above) < REACHED_M:
                self.phase = "descend"
            return above, 1.0
        if self.phase == "descend":
            if np.linalg.norm(tcp - cube) < REACHED_M:
                self.phase = "close"
            return cube, 1.0
        if self.phase == "close":
            self._closing_s += self._period_s
            if self._closing_s >= config.close_s:
                self.phase = "lift"
            return cube, 0.0
        assert self._start is not None
        return self._start + np.array([0.0, 0.0, config.lift_m]), 0.0

    # -- kinematics ------------------------------------------------------------------------

    def _ik_step(
        self,
        world: Privileged,
        hand: tuple[FloatArray, FloatArray, int],
        target: FloatArray,
        cube_quat: FloatArray,
    ) -> FloatArray:
        """Joint target increments for one control period towards ``target``, from the
        ``hand`` that :meth:`_tcp` computed for this step."""
        model, data = world.model, world.data
        tcp, rotation, body = hand
        mujoco.mj_comPos(model, data)
        jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        mujoco.mj_jac(model, data, jacp, jacr, tcp, body)
        dofs = list(world.arm_dofs)
        jacobian = np.vstack([jacp[:, dofs], jacr[:, dofs]])
        velocity = self.config.gain * (target - tcp)
        speed = np.linalg.norm(velocity)
        if speed > self.config.speed_m_s:
            velocity *= self.config.speed_m_s / speed
        turn = np.clip(
            self.config.gain * _orientation_error(rotation, cube_quat), -TURN_RATE, TURN_RATE
        )
        twist = np.concatenate([velocity, turn])
        damped = jacobian @ jacobian.T + DAMPING**2 * np.eye(6)
        rates = jacobian.T @ np.linalg.solve(damped, twist)
        step: FloatArray = rates * self._period_s
        return step


def _gripper(world: Privileged) -> PrivilegedGripper:
    """The robot's first gripper with a tool centre point (refused when there is none)."""
    for gripper in world.grippers:
        if gripper.tcp_body >= 0:
            return gripper
    raise PolicyConfigError(
        "scripted_lift needs a gripper with a tool centre point: set sim.grippers[0].tcp_body "
        "(and tcp_offset_m) in the robot's manifest"
    )


def _tcp(world: Privileged, gripper: PrivilegedGripper) -> tuple[FloatArray, FloatArray, int]:
    """(tool centre point in the world [m], its body's rotation matrix, body id)."""
    model, data, body = world.model, world.data, gripper.tcp_body
    mujoco.mj_kinematics(model, data)
    rotation = data.xmat[body].reshape(3, 3).copy()
    offset = rotation @ np.asarray(gripper.tcp_offset_m, dtype=np.float64)
    return data.xpos[body] + offset, rotation, body


def _orientation_error(rotation: FloatArray, cube_quat: FloatArray) -> FloatArray:
    """Rotation vector [rad, world] from the hand's orientation to fingers-down, turned to
    the cube face nearest the hand's present yaw (a cube looks the same every 90°)."""
    cube = np.empty(9)
    mujoco.mju_quat2Mat(cube, cube_quat)
    cube_x = cube.reshape(3, 3)[:, 0]
    cube_yaw = math.atan2(cube_x[1], cube_x[0])
    hand_yaw = math.atan2(rotation[1, 0], rotation[0, 0])
    quarter = math.pi / 2
    yaw = cube_yaw + quarter * round((hand_yaw - cube_yaw) / quarter)
    wanted = np.array(
        [
            [math.cos(yaw), math.sin(yaw), 0.0],
            [math.sin(yaw), -math.cos(yaw), 0.0],
            [0.0, 0.0, -1.0],
        ]
    )
    error = wanted @ rotation.T
    quat, vector = np.empty(4), np.empty(3)
    mujoco.mju_mat2Quat(quat, error.reshape(9))
    mujoco.mju_quat2Vel(vector, quat, 1.0)
    return vector
