"""End-effector actions on a ROS graph: an ``ee_delta_pose`` or ``ee_pose`` policy's action
as joint targets.

A graph takes joint targets (``/openral/safe_action``), simulated or real. A policy acting
in ``ee_delta_pose`` or ``ee_pose`` (:mod:`openral_sim.ee_modes`) is served by the runner
itself: the robot's own model (alone, never stepped:
:class:`~openral_real.kinematic_twin.KinematicTwin`) is posed at the measured joints of
``/joint_states`` and the one IK (:class:`~openral_sim.ee_modes.EeCommand`, the env's and
the sweep's) steps the arm's targets from the ones sent last towards the TCP pose the deltas
add up to. What goes out is a joint action like any other: the graph's limits, envelope and
E-stop apply to it unchanged."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from openral_core.errors import OpenralError
from openral_core.loaded import LoadedRobot
from openral_mujoco.gripper import slot_map
from openral_mujoco.state import FloatArray
from openral_real.kinematic_twin import KinematicTwin
from openral_sim.ee_modes import DELTA_WIDTH, POSE_WIDTH, PRESETS, EeCommand
from openral_sim.end_effector import EndEffector


class GraphEeActions:
    """End-effector actions of one robot as its joint actions (see the module doc)."""

    def __init__(
        self,
        robot: LoadedRobot,
        period_s: float,
        preset: str = "robosuite",
        mode: str = "ee_delta_pose",
    ) -> None:
        """The robot's model and TCP; ``period_s``: the runner's period [s] (the IK's speed
        cap per action); ``mode``: ``ee_delta_pose`` or ``ee_pose``.

        Raises:
            OpenralError: The robot has no model or no tool centre point (``sim.tcp``).
        """
        wiring = robot.tables.hal_wiring
        if wiring is None or wiring.tcp is None:
            raise OpenralError(
                f"{robot.name} has no tool centre point (sim.tcp): ee_delta_pose actions need one"
            )
        self.twin = KinematicTwin(robot)
        ee = EndEffector(self.twin.model, self.twin.addresses, robot)
        self.command = EeCommand(ee, self.twin.frame_tree(), period_s)
        self.preset = PRESETS[preset]
        self.mode = mode
        self.width = POSE_WIDTH if mode == "ee_pose" else DELTA_WIDTH
        self.names = tuple(joint.name for joint in robot.description.joints)
        gripper = wiring.grippers[0] if wiring.grippers else None
        self._gripper: int | None = None
        self._finger = slot_map("passthrough", 1, (0.0, 1.0), 1.0)
        if gripper is not None and gripper.joint in self.names:
            self._gripper = self.names.index(gripper.joint)
            self._finger = slot_map(
                gripper.read_mode, len(gripper.qpos_addrs), gripper.ctrl_range, gripper.qpos_scale
            )
        self._sent: FloatArray | None = None

    def start(self, hold: FloatArray, joints: Mapping[str, float]) -> None:
        """Start from ``hold`` (the action spec's hold): the TCP reference where it puts
        the arm; ``joints``: the measured joints by name [rad or m]."""
        self._sent = np.asarray(hold, dtype=np.float64).copy()
        self._pose(joints)
        arm = self.command.ee.arm
        self.command.reset(self.twin.data, self._sent[arm])

    @property
    def started(self) -> bool:
        """True after :meth:`start`."""
        return self._sent is not None

    def joint_action(self, action: FloatArray, joints: Mapping[str, float]) -> FloatArray:
        """The joint action of one end-effector action: ``ee_delta_pose``, 7 values in
        [-1, 1]; ``ee_pose``, the TCP's position [m] and quaternion (w, x, y, z) in the base
        frame and the gripper from 0 (closed) to 1 (open).

        Raises:
            OpenralError: Not that many finite values, a zero quaternion; or :meth:`start`
                was not called.
        """
        values = np.asarray(action, dtype=np.float64)
        if values.shape != (self.width,) or not np.all(np.isfinite(values)):
            slots = "x y z qw qx qy qz" if self.mode == "ee_pose" else "dx dy dz rx ry rz"
            raise OpenralError(
                f"an {self.mode} action is {self.width} finite values ({slots} gripper), "
                f"got shape {values.shape}"
            )
        if self._sent is None:
            raise OpenralError(f"{self.mode}: no start pose yet (the action spec's hold)")
        self._pose(joints)
        arm = self.command.ee.arm
        commanded = self._sent[arm]
        try:
            targets, gripper = (
                self.command.absolute(self.twin.data, commanded, values)
                if self.mode == "ee_pose"
                else self.command.delta(
                    self.twin.data, commanded, np.clip(values, -1.0, 1.0), self.preset
                )
            )
        except OpenralError as error:
            raise OpenralError(f"{self.mode}: {error}") from None
        out = self._sent.copy()
        out[arm] = targets
        if self._gripper is not None:
            out[self._gripper] = gripper
        self._sent = out
        return out

    def _pose(self, joints: Mapping[str, float]) -> None:
        """Pose the model at the measured joints (a joint not yet measured: where it was
        last sent; the gripper's slot in its joint's units)."""
        assert self._sent is not None
        angles = np.array([joints.get(name, np.nan) for name in self.names])
        missing = ~np.isfinite(angles)
        angles[missing] = self._sent[missing]
        if self._gripper is not None and missing[self._gripper]:
            angles[self._gripper] = self._finger.joint(float(self._sent[self._gripper]))
        zeros = np.zeros(len(self.names))
        self.twin.pose(angles, zeros, zeros, 0.0)
