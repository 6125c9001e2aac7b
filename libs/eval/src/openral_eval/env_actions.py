"""What an env action is in each action mode: its slots, its bounds, and how it moves the
robot (every mode ends in a joint action through the HAL: the manifest's limits, the E-stop).

- ``joint_position``: one target per action slot (see :mod:`openral_sim.action_bounds`);
  sent as it is.
- ``ee_delta_pose`` and ``ee_pose`` (:mod:`openral_sim.ee_modes`): the tool centre point's
  motion or pose in the base frame and the gripper (an ``ee_pose`` position is bounded by
  the box the arm can reach, :meth:`~openral_sim.ee_modes.EeCommand.reach_box`); the one IK
  (:mod:`openral_sim.end_effector`) gives the arm's targets, and the set point glides to
  them over the period with its speed fed forward, as a trajectory's samples do.

A robot on a mobile base has three more slots in every mode: ``base_vx_m_s``,
``base_vy_m_s``, ``base_wz_rad_s``, within the manifest's velocity limits.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np
from openral_core.loaded import LoadedRobot
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.action import Action, BaseTwist
from openral_mujoco.state import FloatArray
from openral_sim.action_bounds import Bounds, action_bounds
from openral_sim.ee_modes import PRESETS, EeCommand

BASE_SLOTS = ("base_vx_m_s", "base_vy_m_s", "base_wz_rad_s")
"""Names of a mobile base's action slots, after the others."""
DELTA_SLOTS = ("dx", "dy", "dz", "rx", "ry", "rz", "gripper")
POSE_SLOTS = ("x_m", "y_m", "z_m", "qw", "qx", "qy", "qz", "gripper")


class ActionMode(StrEnum):
    """What an env action means (module doc)."""

    JOINT_POSITION = "joint_position"
    EE_DELTA_POSE = "ee_delta_pose"
    EE_POSE = "ee_pose"


class ActionContract:
    """The slots and bounds of one mode, and how an action in it moves the robot."""

    def __init__(
        self,
        hal: SimAttachedHAL,
        robot: LoadedRobot,
        mode: ActionMode,
        ee: EeCommand | None,
        preset: str,
    ) -> None:
        """Raises ValueError for an end-effector mode the scene or robot cannot take, or
        an unknown preset."""
        self.hal, self.robot, self.mode, self.ee = hal, robot, mode, ee
        if mode is not ActionMode.JOINT_POSITION and ee is None:
            raise ValueError(
                f"action mode {mode.value} needs a native scene and a robot with a tool "
                f"centre point (sim.tcp); {robot.name} in this scene has none"
            )
        if preset not in PRESETS:
            raise ValueError(f"unknown ee preset {preset!r}; valid: {', '.join(PRESETS)}")
        self.preset = PRESETS[preset]
        self.base = hal.base is not None
        own = {ActionMode.EE_DELTA_POSE: DELTA_SLOTS, ActionMode.EE_POSE: POSE_SLOTS}
        self.names = own.get(mode, hal.action_names) + (BASE_SLOTS if self.base else ())
        """One name per action value."""
        wiring = robot.tables.hal_wiring
        gripper = wiring.first_gripper if wiring is not None else None
        names = hal.action_names
        self._gripper = names.index(gripper) if gripper in names else None
        self._joint_bounds = action_bounds(hal.env, robot, hal.action_dim)
        handles = hal.mujoco_handles()
        self._reach = (
            ee.reach_box(*handles)
            if ee is not None and handles is not None
            else (np.full(3, -np.inf), np.full(3, np.inf))
        )

    def bounds(self) -> Bounds:
        """(low, high) of every action value."""
        if self.mode is ActionMode.EE_DELTA_POSE:
            low, high = np.full(7, -1.0), np.full(7, 1.0)
        elif self.mode is ActionMode.EE_POSE:  # the position within the arm's reach
            low = np.concatenate([self._reach[0], [-1.0] * 4 + [0.0]])
            high = np.concatenate([self._reach[1], [1.0] * 5])
        else:
            low, high = (bound.copy() for bound in self._joint_bounds)
        base = self.robot.tables.mobile_base
        if self.base and base is not None:
            top = np.array([base.max_linear_velocity_m_s] * 2 + [base.max_angular_velocity_rad_s])
            low, high = np.concatenate([low, -top]), np.concatenate([high, top])
        return low, high

    def reset(self) -> None:
        """A new episode: the end-effector reference starts where the arm is commanded."""
        if self.ee is not None and (handles := self.hal.mujoco_handles()) is not None:
            self.ee.reset(handles[1], self.hal.hold_action()[self.ee.ee.arm])

    def apply(self, values: FloatArray) -> None:
        """Move the robot by one checked action (one control period)."""
        joints, twist = values, None
        if self.base:
            joints, twist = values[:-3], BaseTwist(*(float(v) for v in values[-3:]))
        if self.mode is not ActionMode.JOINT_POSITION:
            joints = self._joint_action(joints)
        action: object = joints
        if twist is not None:
            slots = dict(zip(self.hal.action_names, joints.tolist(), strict=True))
            action = Action(slots=slots, base=twist)
        if self.mode is ActionMode.JOINT_POSITION:
            self.hal.send_action(action)
        else:  # the IK's targets are the next sample of a path: the set point glides there
            self.hal.tick(action, glide=True)

    def _joint_action(self, values: FloatArray) -> FloatArray:
        """The joint action of an end-effector action: the hold, with the IK's arm targets
        and the gripper command."""
        ee, handles = self.ee, self.hal.mujoco_handles()
        if ee is None or handles is None:  # refused at construction
            raise ValueError(f"action mode {self.mode.value} has no end effector here")
        hold = self.hal.hold_action()
        arm = ee.ee.arm
        if self.mode is ActionMode.EE_DELTA_POSE:
            targets, gripper = ee.delta(handles[1], hold[arm], values, self.preset)
        else:
            targets, gripper = ee.absolute(handles[1], hold[arm], values)
        joints = hold.copy()
        joints[arm] = targets
        if self._gripper is not None:
            joints[self._gripper] = gripper
        return np.clip(joints, *self._joint_bounds)
