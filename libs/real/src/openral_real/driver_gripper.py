"""The gripper of an arm with a ros2_control driver: which action slot it is, and how the
slot's value maps to the driver's joint units (metres or radians), as deploy sim's gripper
controller maps them."""

from __future__ import annotations

from openral_core.loaded import LoadedRobot
from openral_core.real_wiring import Ros2ControlWiring
from openral_hal.errors import ConfigurationError
from openral_mujoco.gripper import SlotMap, slot_map, units_mismatch


def gripper_map(robot: LoadedRobot, wiring: Ros2ControlWiring) -> tuple[int, SlotMap] | None:
    """The first gripper's slot and its map to the driver's joint units (None: no gripper).

    Raises:
        ConfigurationError: A gripper action for a gripper whose commands do not share its
            readings' units (no one map converts both).
    """
    hal = robot.tables.hal_wiring
    if hal is None or not hal.grippers:
        return None
    gripper = hal.grippers[0]
    names = [joint.name for joint in robot.description.joints]
    if gripper.joint not in names:
        return None
    mismatch = units_mismatch(gripper.read_mode, gripper.write_mode)
    if mismatch is not None and wiring.gripper_action is not None:
        raise ConfigurationError(f"{robot.name}: no gripper_action for {gripper.joint}: {mismatch}")
    fingers = len(gripper.qpos_addrs)
    axis = slot_map(gripper.read_mode, fingers, gripper.ctrl_range, gripper.qpos_scale)
    return names.index(gripper.joint), axis
