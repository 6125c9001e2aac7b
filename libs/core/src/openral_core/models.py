"""The contract's pydantic models, re-exported from the generated package.

The classes are generated from ``schema/`` by ``just schema-export``; import them from
here so user code never depends on generated module names.
"""

from __future__ import annotations

from openral_generated.models.real_schema import (
    FeetechBus,
    FeetechCalibration,
    FeetechMotor,
    FeetechSettings,
    RealDescription,
    Ros2ControlDriver,
)
from openral_generated.models.robot_schema import (
    Base,
    ContinuousJoint,
    DepthSensor,
    DriveAxes,
    DriveKind,
    ForceTorqueSensor,
    Frames,
    ImuSensor,
    LidarSensor,
    LimitedJoint,
    MobileBase,
    PoseSensor,
    RgbSensor,
    RobotDescription,
    TrajectoryRules,
)
from openral_generated.models.scene_schema import (
    Backend,
    BasePose,
    DeployScene,
    GraspReward,
    GripperHolds,
    LiftReward,
    NativeAssets,
    ObjectAbove,
    ObjectInRegion,
    ObjectRandomization,
    Observation,
    PlaceReward,
    Randomization,
    ReachReward,
    SceneObject,
    SceneOptions,
    SceneSpec,
    Shape,
    TaskReward,
)
from openral_generated.models.sim_schema import (
    GripperReadMode,
    GripperWriteMode,
    PositionControl,
    SimDescription,
    SimGripperDescription,
    ToolCentrePoint,
    TorquePdControl,
)

Joint = LimitedJoint | ContinuousJoint
"""Any joint: ``LimitedJoint`` (revolute/prismatic, with limits) or ``ContinuousJoint``."""
Sensor = RgbSensor | DepthSensor | LidarSensor | ImuSensor | ForceTorqueSensor | PoseSensor
"""Any sensor, discriminated by ``kind``."""
StateSensor = ImuSensor | ForceTorqueSensor | PoseSensor
"""A sensor read from MuJoCo's sensor data at a site (no rendering, no ray casting)."""
SiteSensor = LidarSensor | ImuSensor | ForceTorqueSensor | PoseSensor
"""A sensor that sits at an MJCF site (one of the model's, or one the scene creates)."""
SuccessPredicate = ObjectAbove | ObjectInRegion | GripperHolds
"""Any success predicate of a scene, discriminated by ``kind``."""
RewardTerm = ReachReward | GraspReward | LiftReward | PlaceReward
"""Any term of a scene's dense reward, discriminated by ``kind``."""
SimControl = PositionControl | TorquePdControl
"""Any control law, discriminated by ``mode``."""

__all__ = [
    "Backend",
    "Base",
    "BasePose",
    "ContinuousJoint",
    "DeployScene",
    "DepthSensor",
    "DriveAxes",
    "DriveKind",
    "FeetechBus",
    "FeetechCalibration",
    "FeetechMotor",
    "FeetechSettings",
    "ForceTorqueSensor",
    "Frames",
    "GraspReward",
    "GripperHolds",
    "GripperReadMode",
    "GripperWriteMode",
    "ImuSensor",
    "Joint",
    "LidarSensor",
    "LiftReward",
    "LimitedJoint",
    "MobileBase",
    "NativeAssets",
    "ObjectAbove",
    "ObjectInRegion",
    "ObjectRandomization",
    "Observation",
    "PlaceReward",
    "PoseSensor",
    "PositionControl",
    "Randomization",
    "ReachReward",
    "RealDescription",
    "RewardTerm",
    "RgbSensor",
    "RobotDescription",
    "Ros2ControlDriver",
    "SceneObject",
    "SceneOptions",
    "SceneSpec",
    "Sensor",
    "Shape",
    "SimControl",
    "SimDescription",
    "SimGripperDescription",
    "SiteSensor",
    "StateSensor",
    "SuccessPredicate",
    "TaskReward",
    "ToolCentrePoint",
    "TorquePdControl",
    "TrajectoryRules",
]
