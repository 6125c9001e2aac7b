# GENERATED from schema/ by `just schema-export` -- do not edit.

from __future__ import annotations

from enum import Enum, StrEnum
from typing import Annotated, Literal
from pydantic import ConfigDict, Field
from openral_base import OpenralModel
from typing_extensions import TypeAliasType
from . import sim_schema


class Base(StrEnum):
    """
    How the robot stands: `fixed` is bolted to the world (or to a table); `mobile` drives around (odometry and cmd_vel apply).
    """

    fixed = "fixed"
    mobile = "mobile"


class Type(StrEnum):
    """
    `revolute` (bounded rotation, radians) or `prismatic` (linear, metres).
    """

    revolute = "revolute"
    prismatic = "prismatic"


PositionLimit = TypeAliasType(
    "PositionLimit", Annotated[float, Field(ge=-1000.0, le=1000.0)]
)


class LimitedJoint(OpenralModel):
    """
    A revolute or prismatic joint with position limits.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        str,
        Field(
            examples=["panda_joint1", "shoulder_pan_joint"],
            pattern="^[A-Za-z][A-Za-z0-9_]{0,62}$",
        ),
    ]
    """
    Canonical joint name: the name used on /joint_states, by the safety envelope and by real drivers. Never renamed for a simulator.
    """
    type: Type
    """
    `revolute` (bounded rotation, radians) or `prismatic` (linear, metres).
    """
    position_limits: Annotated[
        list[PositionLimit],
        Field(examples=[[-2.8973, 2.8973]], max_length=2, min_length=2),
    ]
    """
    Lower and upper position limit [rad for revolute, m for prismatic]. The lower bound must be below the upper bound.
    """
    velocity_limit: Annotated[float, Field(gt=0.0, le=1000.0)]
    """
    Largest allowed speed [rad/s for revolute and continuous, m/s for prismatic].
    """
    effort_limit: Annotated[float, Field(gt=0.0, le=100000.0)]
    """
    Largest allowed effort [N·m for revolute and continuous, N for prismatic].
    """
    sim_joint_name: Annotated[
        str | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    The joint's name in the robot's native MJCF model where it differs from the canonical name (for example `joint1` for `panda_joint1`). Absent means the MJCF uses the canonical name. Robosuite's `robot0_` prefixes are stripped automatically and never written here.
    """


class ContinuousJoint(OpenralModel):
    """
    An unbounded revolute joint (no position limits).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        str,
        Field(
            examples=["panda_joint1", "shoulder_pan_joint"],
            pattern="^[A-Za-z][A-Za-z0-9_]{0,62}$",
        ),
    ]
    """
    Canonical joint name: the name used on /joint_states, by the safety envelope and by real drivers. Never renamed for a simulator.
    """
    type: Literal["continuous"]
    """
    `continuous`: unbounded rotation, radians.
    """
    velocity_limit: Annotated[float, Field(gt=0.0, le=1000.0)]
    """
    Largest allowed speed [rad/s for revolute and continuous, m/s for prismatic].
    """
    effort_limit: Annotated[float, Field(gt=0.0, le=100000.0)]
    """
    Largest allowed effort [N·m for revolute and continuous, N for prismatic].
    """
    sim_joint_name: Annotated[
        str | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    The joint's name in the robot's native MJCF model where it differs from the canonical name (for example `joint1` for `panda_joint1`). Absent means the MJCF uses the canonical name. Robosuite's `robot0_` prefixes are stripped automatically and never written here.
    """


class MountAxis(Enum):
    """
    Axis of `mount_body` the camera looks along. Absent: forward (+x) on a torso, head, pelvis or base body, and +z (the usual tool axis) on any other body. UR arms, for example, carry their tool along +y of wrist_3_link.
    """

    field_x = "+x"
    field_x_1 = "-x"
    field_y = "+y"
    field_y_1 = "-y"
    field_z = "+z"
    field_z_1 = "-z"


class RgbSensor(OpenralModel):
    """
    A colour camera; optionally the input of a vision-language-action policy.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        str, Field(examples=["agentview", "wrist"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Sensor name, unique within the robot. Topics are derived from it (`/openral/cameras/<name>/image`).
    """
    kind: Literal["rgb"]
    """
    `rgb`: a colour camera.
    """
    camera: Annotated[str | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")] = (
        None
    )
    """
    MJCF camera the sensor renders from (rgb and depth). Defaults to the sensor name.
    """
    robosuite_camera: Annotated[
        str | None,
        Field(
            examples=["robot0_eye_in_hand"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"
        ),
    ] = None
    """
    Camera in a robosuite environment's model this sensor renders from when a deploy scene uses `backend: robosuite`. Defaults to the sensor name (`agentview` is a camera every robosuite environment has). It sits on the sensor, next to `camera` (the name in the robot's own MJCF), because it is a fact about the robot that every robosuite scene of it shares: robosuite names the cameras it mounts on a robot after the robot's slot, such as `robot0_eye_in_hand` for the first robot's wrist camera.
    """
    mount_body: Annotated[
        str | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) the camera is rigidly attached to, such as the hand for a wrist camera. Absent means a fixed camera placed by the scene.
    """
    mount_axis: MountAxis | None = None
    """
    Axis of `mount_body` the camera looks along. Absent: forward (+x) on a torso, head, pelvis or base body, and +z (the usual tool axis) on any other body. UR arms, for example, carry their tool along +y of wrist_3_link.
    """
    fovy_deg: Annotated[float, Field(gt=0.0, lt=180.0)] = 45.0
    """
    Vertical field of view [deg] of a camera the scene creates.
    """
    width: Annotated[int, Field(ge=16, le=4096)]
    """
    Image width [px], 16 to 4096.
    """
    height: Annotated[int, Field(ge=16, le=4096)]
    """
    Image height [px], 16 to 4096.
    """
    rate_hz: Annotated[float, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000; the sim bridge's camera rate is a runtime setting.
    """
    frame_id: Annotated[
        str,
        Field(
            examples=["agentview_optical_frame"],
            pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$",
        ),
    ]
    """
    TF frame of the sensor's optical centre, copied into message headers.
    """
    vla_feature_key: Annotated[
        str | None,
        Field(
            examples=["observation.images.camera1"],
            pattern="^observation\\.images\\.[a-z][a-z0-9_]{0,62}$",
        ),
    ] = None
    """
    LeRobot-style observation key a vision-language-action policy expects this camera under, `observation.images.<slot>`. Only for rgb sensors. The slot (the part after the last dot) is what policies look frames up by.
    """


RangeMItem = TypeAliasType("RangeMItem", Annotated[float, Field(ge=0.0, le=1000.0)])


class DepthSensor(OpenralModel):
    """
    A depth camera; published as a depth image and a point cloud.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        str, Field(examples=["agentview", "wrist"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Sensor name, unique within the robot. Topics are derived from it (`/openral/cameras/<name>/image`).
    """
    kind: Literal["depth"]
    """
    `depth`: a depth camera (depth image and point cloud).
    """
    camera: Annotated[str | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")] = (
        None
    )
    """
    MJCF camera the sensor renders from (rgb and depth). Defaults to the sensor name.
    """
    mount_body: Annotated[
        str | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) the camera is rigidly attached to, such as the hand for a wrist camera. Absent means a fixed camera placed by the scene.
    """
    mount_axis: MountAxis | None = None
    """
    Axis of `mount_body` the camera looks along. Absent: forward (+x) on a torso, head, pelvis or base body, and +z (the usual tool axis) on any other body. UR arms, for example, carry their tool along +y of wrist_3_link.
    """
    fovy_deg: Annotated[float, Field(gt=0.0, lt=180.0)] = 45.0
    """
    Vertical field of view [deg] of a camera the scene creates.
    """
    width: Annotated[int, Field(ge=16, le=4096)]
    """
    Image width [px], 16 to 4096.
    """
    height: Annotated[int, Field(ge=16, le=4096)]
    """
    Image height [px], 16 to 4096.
    """
    rate_hz: Annotated[float, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000; the sim bridge's camera rate is a runtime setting.
    """
    frame_id: Annotated[
        str,
        Field(
            examples=["agentview_optical_frame"],
            pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$",
        ),
    ]
    """
    TF frame of the sensor's optical centre, copied into message headers.
    """
    range_m: Annotated[
        list[RangeMItem] | None,
        Field(examples=[[0.05, 10.0]], max_length=2, min_length=2),
    ] = None
    """
    Shortest and longest measured distance [m] (depth and lidar).
    """


AngleRangeDegItem = TypeAliasType(
    "AngleRangeDegItem", Annotated[float, Field(ge=-360.0, le=360.0)]
)


class LidarSensor(OpenralModel):
    """
    A planar lidar: rays cast from an MJCF site.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        str, Field(examples=["agentview", "wrist"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Sensor name, unique within the robot. Topics are derived from it (`/openral/cameras/<name>/image`).
    """
    kind: Literal["lidar"]
    """
    `lidar`: a planar laser scanner.
    """
    site: Annotated[str, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    MJCF site the lidar's rays start from (lidar only).
    """
    width: Annotated[int, Field(ge=1, le=4096)]
    """
    Number of rays in one scan, 1 to 4096.
    """
    height: Annotated[int, Field(ge=1, le=1)]
    """
    Scan lines: always 1 (a planar lidar).
    """
    rate_hz: Annotated[float, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000; the sim bridge's camera rate is a runtime setting.
    """
    frame_id: Annotated[
        str,
        Field(
            examples=["agentview_optical_frame"],
            pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$",
        ),
    ]
    """
    TF frame of the sensor's optical centre, copied into message headers.
    """
    range_m: Annotated[
        list[RangeMItem], Field(examples=[[0.05, 10.0]], max_length=2, min_length=2)
    ]
    """
    Shortest and longest measured distance [m] (depth and lidar).
    """
    angle_range_deg: Annotated[
        list[AngleRangeDegItem],
        Field(examples=[[-135.0, 135.0]], max_length=2, min_length=2),
    ]
    """
    First and last ray angle [deg] of a lidar scan, counter-clockwise about the site's z axis.
    """


class RobotDescription(OpenralModel):
    """
    Everything openral knows about one robot arm, written once in robots/<id>/robot.yaml. The HAL, the simulated scene and the ROS 2 graph are all derived from this document.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    schema_version: Literal["0.1"]
    """
    Version of this contract. Only "0.1" exists; additive fields keep the version.
    """
    name: Annotated[
        str, Field(examples=["franka_panda", "ur5e"], pattern="^[a-z][a-z0-9_]{1,62}$")
    ]
    """
    Robot id: lower-case snake case, equal to the name of the folder under robots/ that holds this file. Used on the command line (`openral robot show <name>`) and as the default ROS namespace.
    """
    display_name: Annotated[
        str, Field(examples=["Franka Emika Panda"], max_length=80, min_length=1)
    ]
    """
    Human-readable name shown in tables and docs.
    """
    joints: Annotated[
        list[LimitedJoint | ContinuousJoint], Field(max_length=64, min_length=1)
    ]
    """
    The robot's controllable joints in canonical order. This order is the order of JointState messages, of HAL state vectors and of joint-space actions. A gripper is listed as one joint (its driving finger or jaw).
    """
    sensors: Annotated[
        list[RgbSensor | DepthSensor | LidarSensor],
        Field(max_length=32, validate_default=True),
    ] = []
    """
    Sensors the robot carries or that its scenes provide for it (cameras, depth cameras, lidars). Each becomes a ROS topic under deploy sim.
    """
    base: Base
    """
    How the robot stands: `fixed` is bolted to the world (or to a table); `mobile` drives around (odometry and cmd_vel apply).
    """
    sim: sim_schema.SimDescription | None = None
    """
    MuJoCo wiring: where the model comes from and how joints map to qpos, qvel and actuators. Absent for robots that have no simulation model.
    """
