"""The end-effector target a control loop follows: deploy sim's ``ee_pose`` mode.

A client puts the tool centre point (TCP) somewhere by publishing one pose in the robot's
base frame (``/openral/ee_target``, see :mod:`openral_bridge.ee_bridge`). The target stays
in force until something else commands the arm: every control tick asks
:meth:`EeTargetFollower.next_action` for the coming period's action, which is one step of
the same IK an env's ``ee_pose`` action takes (:meth:`openral_sim.ee_modes.EeCommand.absolute`,
from the commanded targets, inside the manifest's position and velocity limits): the hold
action with the arm's slots set to the step's targets, which the HAL glides to. Repeated
ticks close on the target and then hold it; a target out of reach is approached to the edge
of the workspace and held there. The grippers keep their commands.

A ``safe_action``, a joint trajectory, the E-stop, a reset and a failed tick end the target
(:meth:`EeTargetFollower.cancel`). Every method may be called from any thread;
:meth:`next_action` runs holding the HAL's lock (it reads the live scene).
"""

from __future__ import annotations

import math
import threading

import numpy as np
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.errors import ActionRejected
from openral_mujoco.state import FloatArray
from openral_sim.ee_modes import EeCommand, unit_quaternion

from openral_bridge.trajectory_follower import DesiredPoint

POSE_WIDTH = 7
"""A target: position x, y, z [m] and quaternion w, x, y, z in the base frame."""
_FIELDS = tuple(f"position.{a}" for a in "xyz") + tuple(f"orientation.{a}" for a in "wxyz")


class EeTargetRefused(ValueError):
    """A target that cannot be followed (the message says why); nothing changed."""


def checked_pose(position: tuple[float, ...], quat_wxyz: tuple[float, ...]) -> FloatArray:
    """The 7-value target of a position [m] and a quaternion (normalised here).

    Raises:
        EeTargetRefused: A value is not finite, or the quaternion has no direction.
    """
    values = [float(v) for v in (*position, *quat_wxyz)]
    for name, value in zip(_FIELDS, values, strict=True):
        if not math.isfinite(value):
            raise EeTargetRefused(f"pose.{name} is {value}; expected a finite number")
    pose = np.array(values, dtype=np.float64)
    try:
        pose[3:] = unit_quaternion(pose[3:], "pose.orientation")
    except ActionRejected as error:
        raise EeTargetRefused(str(error)) from None
    return pose


class EeTargetFollower:
    """The TCP target of one control loop (see the module doc)."""

    def __init__(self, hal: SimAttachedHAL, ee: EeCommand) -> None:
        """Follow targets with ``ee`` (the HAL's own end-effector command)."""
        self.hal, self.ee = hal, ee
        self.names = tuple(hal.action_names[i] for i in ee.ee.arm)
        """The arm's action slots the IK sets."""
        self._lock = threading.Lock()
        self._target: FloatArray | None = None
        self.accepted = 0
        self.cancelled = 0
        """Targets ended by another command, the E-stop, a reset or a failed tick."""

    @property
    def base_frame(self) -> str:
        """The frame a target is stated in (the robot's base frame on ``/tf``)."""
        return self.ee.frames.tree.base

    @property
    def active(self) -> bool:
        """True while a target is in force."""
        with self._lock:
            return self._target is not None

    def submit(self, pose: FloatArray) -> None:
        """Make ``pose`` (from :func:`checked_pose`) the target from the next tick on."""
        with self._lock:
            self._target = np.array(pose, dtype=np.float64)
            self.accepted += 1

    def cancel(self, reason: str = "cancelled") -> bool:
        """End the target; True when one was in force (``reason`` is for the caller's log)."""
        del reason
        with self._lock:
            ended, self._target = self._target is not None, None
            self.cancelled += int(ended)
        return ended

    def next_action(
        self, hold: FloatArray, now_s: float, period_s: float
    ) -> tuple[FloatArray, DesiredPoint] | None:
        """The action of the coming period towards the target and the arm's desired point,
        or None with no target (holding the HAL lock).

        Args:
            hold: The hold action (the targets in force), one value per slot.
            now_s: Simulated time at the start of the period [s].
            period_s: The control period [s].
        """
        with self._lock:
            target = self._target
        handles = self.hal.mujoco_handles()
        if target is None or handles is None:
            return None
        arm = self.ee.ee.arm
        commanded = np.array(hold, dtype=np.float64)
        step = np.concatenate([target, [0.0]])  # the gripper value is not used here
        targets, _ = self.ee.absolute(handles[1], commanded[arm], step)
        action = commanded.copy()
        action[arm] = targets
        speed = (targets - commanded[arm]) / period_s
        return action, DesiredPoint(self.names, targets.copy(), speed, now_s + period_s)
