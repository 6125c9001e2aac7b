"""``scripted_lift``: a privileged scripted policy that lifts a cube from above, in
end-effector actions.

It acts in ``ee_delta_pose`` (the robosuite preset: full scale 0.05 m and 0.5 rad a step,
-1 opens the gripper, +1 closes it), so the one IK of :mod:`openral_sim.end_effector` turns
its motions into joint targets under the manifest's limits, and nothing of any one robot is
written here: the tool centre point comes from the observation (``tcp_pose``, base frame,
from the manifest's ``sim.tcp``) and the cube's pose from the privileged state, brought
into the base frame. It moves the tool centre point through four phases:

1. ``approach``: ``approach_m`` above the cube, fingers pointing down and turned to the
   cube's nearest face;
2. ``descend``: to the cube's centre;
3. ``close``: the gripper closes for ``close_s``;
4. ``lift``: ``lift_m`` above where the cube started.

Each step asks for ``gain`` times the remaining error, at most ``speed_m_s`` (the lift:
``lift_speed_m_s``) and a turn rate of 1.5 rad/s. It uses no randomness and no wall clock:
the same episode gives the same actions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from openral_mujoco.state import FloatArray
from openral_sim.ee_modes import PRESETS
from openral_sim.frame_tree import pose_in_frame

from openral_eval.observation_keys import TCP_POSE, vector_of
from openral_eval.policy import Observation, PolicyConfigError, privileged_of, time_of

PHASES = ("approach", "descend", "close", "lift")
TURN_RATE = 1.5
"""Largest commanded turn rate [rad/s]."""
REACHED_M = 0.008
"""A phase's target counts as reached within this distance [m]."""
PRESET = PRESETS["robosuite"]
"""The ``ee_delta_pose`` convention it acts in."""
OPEN, CLOSE = -1.0, 1.0
"""Its gripper values (robosuite's signs)."""


@dataclass(frozen=True)
class LiftConfig:
    """Parameters of :class:`ScriptedLift` (``-p key=value``)."""

    object: str = "red_cube"
    """The scene object to lift."""
    approach_m: float = 0.10
    lift_m: float = 0.12
    speed_m_s: float = 0.35
    lift_speed_m_s: float = 0.15
    """Top speed of the lift [m/s]: a gentler start than the approach's, so the cube stays
    between the fingers (the menagerie Panda's gripper squeezes with about 5 N)."""
    close_s: float = 0.6
    gain: float = 6.0
    """Proportional gain of the Cartesian error [1/s]."""

    def __post_init__(self) -> None:
        if min(self.speed_m_s, self.lift_speed_m_s, self.gain) <= 0 or self.close_s < 0:
            raise PolicyConfigError(
                "scripted_lift speed_m_s, lift_speed_m_s and gain must be > 0, close_s >= 0"
            )


class ScriptedLift:
    """The four-phase lift of the module doc; one instance per episode."""

    config_type = LiftConfig
    """Its parameters (``--param key=value``)."""

    needs_privileged = True
    """It reads the cube's pose from the simulation (evaluation episodes only)."""
    required_slots: tuple[str, ...] = ()
    action_mode = "ee_delta_pose"
    """Its actions move the tool centre point (robosuite preset)."""

    def __init__(self, config: LiftConfig) -> None:
        self.config = config
        self.phase = PHASES[0]
        self._closing_s = 0.0
        self._start: FloatArray | None = None
        self._period_s = 0.05
        self._last_time_s: float | None = None

    def act(self, obs: Observation) -> FloatArray:
        """The next action: the TCP's motion towards the phase's target, and the gripper."""
        world = privileged_of(obs)
        tcp = vector_of(obs, TCP_POSE)
        if world is None or tcp is None or world.base is None:
            raise PolicyConfigError(
                "scripted_lift needs privileged state and the robot's tcp_pose "
                "(episodes on a native scene, a manifest with sim.tcp)"
            )
        now = time_of(obs)
        if self._last_time_s is not None and now > self._last_time_s:
            self._period_s = now - self._last_time_s  # the control period
        self._last_time_s = now
        if self.config.object not in world.objects:
            have = ", ".join(sorted(world.objects)) or "none"
            raise PolicyConfigError(f"no scene object {self.config.object!r}; objects: {have}")
        cube, cube_quat = pose_in_frame(world.base, world.objects[self.config.object])
        if self._start is None:
            self._start = cube.copy()
        target, gripper = self._phase_target(cube, tcp[:3])
        return np.concatenate([self._motion(tcp, target, cube_quat), [gripper]])

    # -- phases ----------------------------------------------------------------------------

    def _phase_target(self, cube: FloatArray, tcp: FloatArray) -> tuple[FloatArray, float]:
        """Where the gripper's centre (now at ``tcp``) should go, and the gripper value."""
        config = self.config
        above = cube + np.array([0.0, 0.0, config.approach_m])
        if self.phase == "approach":
            if np.linalg.norm(tcp - above) < REACHED_M:
                self.phase = "descend"
            return above, OPEN
        if self.phase == "descend":
            if np.linalg.norm(tcp - cube) < REACHED_M:
                self.phase = "close"
            return cube, OPEN
        if self.phase == "close":
            self._closing_s += self._period_s
            if self._closing_s >= config.close_s:
                self.phase = "lift"
            return cube, CLOSE
        assert self._start is not None
        return self._start + np.array([0.0, 0.0, config.lift_m]), CLOSE

    def _motion(self, tcp: FloatArray, target: FloatArray, cube_quat: FloatArray) -> FloatArray:
        """The six motion values of one step, in the preset's full scale."""
        velocity = self.config.gain * (target - tcp[:3])
        speed = np.linalg.norm(velocity)
        top = self.config.lift_speed_m_s if self.phase == "lift" else self.config.speed_m_s
        if speed > top:
            velocity *= top / speed
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, tcp[3:])
        error = _orientation_error(rotation.reshape(3, 3), cube_quat)
        turn = np.clip(self.config.gain * error, -TURN_RATE, TURN_RATE)
        move = velocity * self._period_s / PRESET.translation_m
        spin = turn * self._period_s / PRESET.rotation_rad
        motion: FloatArray = np.clip(np.concatenate([move, spin]), -1.0, 1.0)
        return motion


def _orientation_error(rotation: FloatArray, cube_quat: FloatArray) -> FloatArray:
    """Rotation vector [rad] from the hand's orientation to fingers-down, turned to the
    cube face nearest the hand's present yaw (a cube looks the same every 90°)."""
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
