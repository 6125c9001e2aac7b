"""openral core: the robot contract, loaded and validated in one place.

Typical use::

    from openral_core import open_robot_by_id
    robot = open_robot_by_id("franka_panda")    # manifest + folder + generated tables
    wiring = robot.tables.hal_wiring
"""

from openral_core.errors import Issue, ManifestError, OpenralError, StaleTables, UnknownRobot
from openral_core.loaded import LoadedRobot, loaded_robot, open_robot, open_robot_by_id
from openral_core.loader import load_robot, load_scene, validate_robot_file
from openral_core.models import DeployScene, RobotDescription, SimDescription
from openral_core.registry import load_robot_by_id, manifest_path, robot_ids
from openral_core.tables import (
    GripperWiring,
    HalWiring,
    MobileBaseWiring,
    RobotTables,
    VlaSlot,
    hal_wiring,
    joint_name_map,
    manifest_sha256,
    mobile_base_wiring,
    robot_tables,
    vla_slot,
    vla_slots,
)

__all__ = [
    "DeployScene",
    "GripperWiring",
    "HalWiring",
    "Issue",
    "LoadedRobot",
    "ManifestError",
    "MobileBaseWiring",
    "OpenralError",
    "RobotDescription",
    "RobotTables",
    "SimDescription",
    "StaleTables",
    "UnknownRobot",
    "VlaSlot",
    "hal_wiring",
    "joint_name_map",
    "load_robot",
    "load_robot_by_id",
    "load_scene",
    "loaded_robot",
    "manifest_path",
    "manifest_sha256",
    "mobile_base_wiring",
    "open_robot",
    "open_robot_by_id",
    "robot_ids",
    "robot_tables",
    "validate_robot_file",
    "vla_slot",
    "vla_slots",
]
