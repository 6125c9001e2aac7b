"""The contract's pydantic models, re-exported from the generated package.

The classes are generated from ``schema/`` by ``just schema-export``; import them from
here so user code never depends on generated module names.
"""

from __future__ import annotations

from openral_generated.models.robot_schema import Base, Joint, RobotDescription, Sensor
from openral_generated.models.robot_schema import Kind as SensorKind
from openral_generated.models.robot_schema import Type as JointType
from openral_generated.models.scene_schema import (
    BasePose,
    DeployScene,
    Observation,
    SceneObject,
    SceneOptions,
    SceneSpec,
)
from openral_generated.models.sim_schema import (
    GripperReadMode,
    GripperWriteMode,
    SimControl,
    SimDescription,
    SimGripperDescription,
)
from openral_generated.models.sim_schema import Mode as ControlMode

__all__ = [
    "Base",
    "BasePose",
    "ControlMode",
    "DeployScene",
    "GripperReadMode",
    "GripperWriteMode",
    "Joint",
    "JointType",
    "Observation",
    "RobotDescription",
    "SceneObject",
    "SceneOptions",
    "SceneSpec",
    "Sensor",
    "SensorKind",
    "SimControl",
    "SimDescription",
    "SimGripperDescription",
]
