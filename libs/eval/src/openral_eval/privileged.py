"""Privileged observations: what a scripted policy may know that a camera-only one cannot.

A policy that sets ``needs_privileged = True`` gets ``obs["privileged"]`` on every step of
an episode on a native scene (never under ROS: the rskill runner refuses such a policy):
the scene's model, a scratch copy of the simulation state it may compute on
(``mj_kinematics``, Jacobians), the world pose of every scene object and of the robot's base
frame, and the action slots of the robot's grippers (the tool centre point's pose is the
observation's ``tcp_pose``).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
from openral_mujoco.state import FloatArray

Pose = tuple[FloatArray, FloatArray]
"""World position [m] and orientation quaternion (w, x, y, z)."""


@dataclass(frozen=True)
class PrivilegedGripper:
    """One gripper of the manifest, located in the scene."""

    slot: int
    """Its action slot (write mode ``normalised``: 1 open, 0 closed)."""


@dataclass(frozen=True)
class Privileged:
    """The simulation behind one observation (see the module doc)."""

    model: mujoco.MjModel
    data: mujoco.MjData
    """A copy of the state at this step, the policy's to change."""
    objects: dict[str, Pose]
    """Scene object name (as in the scene file) → its world pose."""
    arm_slots: tuple[int, ...]
    """Action slots that are arm joints (position targets), in manifest order."""
    arm_dofs: tuple[int, ...]
    """Each of those joints' degree of freedom in :attr:`model` (Jacobian columns)."""
    grippers: tuple[PrivilegedGripper, ...] = ()
    """The manifest's grippers, in manifest order."""
    base: Pose | None = None
    """The world pose of the robot's base frame (the frame ``tcp_pose`` is stated in)."""
