"""Servo readings and goals ↔ the manifest's units, for one robot's motors.

Three spaces meet here: the servos' steps (present positions and goals, through each
motor's :class:`~openral_real.calibration.JointScale`), joint angles [rad] (what the motion
envelope limits), and the manifest's units (what ``read_state`` reports and actions carry):
an arm joint's manifest unit is its angle, a gripper's is its ``sim.grippers`` convention,
read through its ``read_mode`` and written through its ``write_mode`` exactly as the
simulation does, so a policy sees and commands the same numbers on both.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from openral_core.loaded import LoadedRobot
from openral_mujoco.gripper import gripper_command, gripper_ctrl, reading_map
from openral_mujoco.state import FloatArray, JointStateSample

from openral_real.calibration import JointScale
from openral_real.feetech_bus import ServoReading


@dataclass(frozen=True)
class _Gripper:
    slot: int
    read_offset: float
    read_weight: float
    write_mode: str
    ctrl_range: tuple[float, float]


class ServoUnits:
    """Conversions between one robot's servos and its manifest (see the module doc)."""

    def __init__(self, robot: LoadedRobot, scales: tuple[JointScale, ...]) -> None:
        """``scales``: one per manifest joint, in manifest order."""
        self.names = tuple(joint.name for joint in robot.description.joints)
        self.scales = scales
        self.effort_limit = np.array([j.effort_limit for j in robot.description.joints])
        self._grippers = _grippers(robot, self.names)

    def angles(self, readings: Sequence[ServoReading]) -> FloatArray:
        """Joint angles [rad] of a present block."""
        return np.array([s.angle(r.position) for s, r in zip(self.scales, readings, strict=True)])

    def physical(
        self, readings: Sequence[ServoReading]
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint angles [rad], rates [rad/s] and efforts [N m] of a present block (a
        gripper's jaw as a joint; efforts from the servos' loads, as shares of their stall
        torque)."""
        pairs = list(zip(self.scales, readings, strict=True))
        angles = np.array([s.angle(r.position) for s, r in pairs])
        rates = np.array([s.rate(r.velocity) for s, r in pairs])
        signs = np.array([s.sign for s in self.scales])
        efforts = np.array([r.load for r in readings], float) / 1000.0 * self.effort_limit * signs
        return angles, rates, efforts

    def sample(self, readings: Sequence[ServoReading], stamp_ns: int) -> JointStateSample:
        """The manifest's joint state of a present block read at ``stamp_ns`` [ns, system
        clock]: :meth:`physical`, a gripper in its read mode."""
        positions, velocities, efforts = self.physical(readings)
        for g in self._grippers:
            positions[g.slot] = g.read_offset + g.read_weight * positions[g.slot]
            velocities[g.slot] *= g.read_weight
        return JointStateSample(self.names, positions, velocities, efforts, stamp_ns, None, False)

    def action_angles(self, action: FloatArray) -> FloatArray:
        """The joint angles [rad] a manifest action commands (a gripper's command through
        its write mode)."""
        angles = np.asarray(action, dtype=np.float64).copy()
        for g in self._grippers:
            angles[g.slot] = gripper_ctrl(g.write_mode, float(angles[g.slot]), g.ctrl_range)
        return angles

    def action_of(self, angles: FloatArray) -> FloatArray:
        """The manifest action that holds the joints at ``angles`` [rad]."""
        action = np.asarray(angles, dtype=np.float64).copy()
        for g in self._grippers:
            action[g.slot] = gripper_command(g.write_mode, float(angles[g.slot]), g.ctrl_range)
        return action

    def steps(self, angles: FloatArray) -> list[int]:
        """Every motor's goal [steps] for ``angles`` [rad]."""
        return [s.steps(float(a)) for s, a in zip(self.scales, angles, strict=True)]


def _grippers(robot: LoadedRobot, names: tuple[str, ...]) -> tuple[_Gripper, ...]:
    wiring = robot.tables.hal_wiring
    found = []
    for g in wiring.grippers if wiring is not None else ():
        read = reading_map(g.read_mode, len(g.qpos_addrs), g.ctrl_range, g.qpos_scale)
        found.append(
            _Gripper(names.index(g.joint), read.offset, read.weights[0], g.write_mode, g.ctrl_range)
        )
    return tuple(found)
