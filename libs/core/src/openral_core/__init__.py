"""openral core: the robot contract, loaded and validated in one place.

Typical use::

    from openral_core import open_robot_by_id
    robot = open_robot_by_id("franka_panda")    # manifest + folder + generated tables
    wiring = robot.tables.hal_wiring

The names below are imported on first use (PEP 562), so a command that needs only the
error types, or nothing of the contract (``openral --help``, ``openral ros ...``), does not
pay for pydantic, jsonschema and ruamel (about 1.2 s of a CLI start on a 2-core machine).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
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

_WHERE = {
    "DeployScene": "openral_core.models",
    "GripperWiring": "openral_core.tables",
    "HalWiring": "openral_core.tables",
    "Issue": "openral_core.errors",
    "LoadedRobot": "openral_core.loaded",
    "ManifestError": "openral_core.errors",
    "MobileBaseWiring": "openral_core.tables",
    "OpenralError": "openral_core.errors",
    "RobotDescription": "openral_core.models",
    "RobotTables": "openral_core.tables",
    "SimDescription": "openral_core.models",
    "StaleTables": "openral_core.errors",
    "UnknownRobot": "openral_core.errors",
    "VlaSlot": "openral_core.tables",
    "hal_wiring": "openral_core.tables",
    "joint_name_map": "openral_core.tables",
    "load_robot": "openral_core.loader",
    "load_robot_by_id": "openral_core.registry",
    "load_scene": "openral_core.loader",
    "loaded_robot": "openral_core.loaded",
    "manifest_path": "openral_core.registry",
    "manifest_sha256": "openral_core.tables",
    "mobile_base_wiring": "openral_core.tables",
    "open_robot": "openral_core.loaded",
    "open_robot_by_id": "openral_core.loaded",
    "robot_ids": "openral_core.registry",
    "robot_tables": "openral_core.tables",
    "validate_robot_file": "openral_core.loader",
    "vla_slot": "openral_core.tables",
    "vla_slots": "openral_core.tables",
}
"""Each public name and the module it comes from."""

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


def __getattr__(name: str) -> object:
    """Import ``name`` from its module on first use (PEP 562) and keep it here."""
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'openral_core' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
