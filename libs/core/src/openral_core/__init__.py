"""openral core: the robot contract, loaded and validated in one place.

Typical use::

    from openral_core import load_robot_by_id, robot_tables
    robot = load_robot_by_id("franka_panda")
    wiring = robot_tables(robot).hal_wiring
"""

from openral_core.errors import Issue, ManifestError, OpenralError, UnknownRobot
from openral_core.loader import load_robot, load_scene, validate_robot_file
from openral_core.models import DeployScene, RobotDescription, SimDescription
from openral_core.registry import load_robot_by_id, manifest_path, robot_ids
from openral_core.tables import (
    GripperWiring,
    HalWiring,
    RobotTables,
    VlaSlot,
    hal_wiring,
    joint_name_map,
    robot_tables,
    vla_slot,
    vla_slots,
)

__all__ = [
    "DeployScene",
    "GripperWiring",
    "HalWiring",
    "Issue",
    "ManifestError",
    "OpenralError",
    "RobotDescription",
    "RobotTables",
    "SimDescription",
    "UnknownRobot",
    "VlaSlot",
    "hal_wiring",
    "joint_name_map",
    "load_robot",
    "load_robot_by_id",
    "load_scene",
    "manifest_path",
    "robot_ids",
    "robot_tables",
    "validate_robot_file",
    "vla_slot",
    "vla_slots",
]
