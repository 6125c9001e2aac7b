"""A parallel gripper as one axis: its URDF joint position against its action slot.

``/joint_states`` and GripperCommand give the gripper's joint position (the first finger's:
metres for a prismatic finger, radians for a jaw); the HAL reads and commands the gripper in
the manifest's read and write modes (:mod:`openral_mujoco.gripper`). Both modes are affine in
the finger positions, so with every finger at ``q`` the reading is ``offset + gain * q`` and
a normalised command is that same value. A write mode that does not share the read mode's
units (a ``passthrough`` command with a normalised reading, or the reverse) has no such map:
such a robot gets no gripper action, and the log says why.
"""

from __future__ import annotations

from dataclasses import dataclass

from openral_core.loaded import LoadedRobot
from openral_core.models import LimitedJoint
from openral_mujoco.gripper import SlotMap, slot_map, units_mismatch
from openral_mujoco.state import JointStateSample


@dataclass(frozen=True)
class GripperAxis:
    """One gripper: joint name, action slot, limits and the reading's affine map."""

    joint: str
    slot: int
    limits: tuple[float, float]
    """The manifest's position limits of the joint (URDF units)."""
    map: SlotMap
    """The slot against the joint position (every finger at it)."""

    def command(self, position: float) -> float:
        """The action slot's value that sends the gripper to ``position``."""
        return self.map.slot(position)

    def position(self, state: JointStateSample) -> float:
        """The joint position of a HAL reading."""
        return self.map.joint(float(state.positions[self.slot]))

    def speed(self, state: JointStateSample) -> float:
        """The joint speed of a HAL reading [unit/s]."""
        return float(state.velocities[self.slot]) / self.map.gain

    def effort(self, state: JointStateSample) -> float:
        """The gripper's effort in a HAL reading (N or N·m)."""
        return float(state.efforts[self.slot])


def gripper_axis(robot: LoadedRobot, action_names: tuple[str, ...]) -> GripperAxis | str | None:
    """The first gripper of ``robot`` as an axis, why it cannot have a gripper action, or
    None for a robot without a gripper."""
    wiring = robot.tables.hal_wiring
    if wiring is None or not wiring.grippers:
        return None
    gripper = wiring.grippers[0]
    if gripper.joint not in action_names:
        return f"the gripper {gripper.joint} is no slot of this scene's action"
    mismatch = units_mismatch(gripper.read_mode, gripper.write_mode)
    if mismatch is not None:
        return mismatch
    joint = next(j for j in robot.description.joints if j.name == gripper.joint)
    if not isinstance(joint, LimitedJoint):
        return f"the gripper {gripper.joint} is continuous: a GripperCommand needs limits"
    low, high = joint.position_limits
    return GripperAxis(
        joint=gripper.joint,
        slot=action_names.index(gripper.joint),
        limits=(float(low), float(high)),
        map=slot_map(
            gripper.read_mode, len(gripper.qpos_addrs), gripper.ctrl_range, gripper.qpos_scale
        ),
    )
