# GENERATED from schema/ by `just schema-export` -- do not edit.

from __future__ import annotations

from enum import Enum, StrEnum
from pydantic import ConfigDict, Field, StrictFloat, StrictInt, StrictStr
from typing import Annotated, Literal
from openral_base import OpenralModel
from typing_extensions import TypeAliasType
from . import real_schema, sim_schema


class Base(StrEnum):
    """
    How the robot stands: `fixed` is bolted to the world (or to a table); `mobile` drives around (odometry and cmd_vel apply): on a wheeled base described by `mobile_base`, or, with `sim.floating_base`, on its own legs.
    """

    fixed = "fixed"
    mobile = "mobile"


MjcfName = TypeAliasType(
    "MjcfName", Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
)
"""
A name of an element (joint, body, camera, site) in an MJCF model.
"""


class Type(StrEnum):
    """
    `revolute` (bounded rotation, radians) or `prismatic` (linear, metres).
    """

    revolute = "revolute"
    prismatic = "prismatic"


PositionLimit = TypeAliasType(
    "PositionLimit", Annotated[StrictFloat, Field(ge=-1000.0, le=1000.0)]
)


class LimitedJoint(OpenralModel):
    """
    A revolute or prismatic joint with position limits.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr,
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
    velocity_limit: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)]
    """
    Largest allowed speed [rad/s for revolute and continuous, m/s for prismatic].
    """
    effort_limit: Annotated[StrictFloat, Field(gt=0.0, le=100000.0)]
    """
    Largest allowed effort [N·m for revolute and continuous, N for prismatic].
    """
    sim_joint_name: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
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
        StrictStr,
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
    velocity_limit: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)]
    """
    Largest allowed speed [rad/s for revolute and continuous, m/s for prismatic].
    """
    effort_limit: Annotated[StrictFloat, Field(gt=0.0, le=100000.0)]
    """
    Largest allowed effort [N·m for revolute and continuous, N for prismatic].
    """
    sim_joint_name: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
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


MountPositionMItem = TypeAliasType(
    "MountPositionMItem", Annotated[StrictFloat, Field(ge=-10.0, le=10.0)]
)


class RgbSensor(OpenralModel):
    """
    A colour camera; optionally the input of a vision-language-action policy.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr,
        Field(examples=["agentview", "wrist"], pattern="^[a-z][a-z0-9_]{0,62}$"),
    ]
    """
    Sensor name, unique within the robot. Topics are derived from it (`/openral/cameras/<name>/image`).
    """
    kind: Literal["rgb"]
    """
    `rgb`: a colour camera.
    """
    camera: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF camera the sensor renders from (rgb and depth). Defaults to the sensor name.
    """
    robosuite_camera: Annotated[
        StrictStr | None,
        Field(
            examples=["robot0_eye_in_hand"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"
        ),
    ] = None
    """
    Camera in a robosuite environment's model this sensor renders from when a deploy scene uses `backend: robosuite`. Defaults to the sensor name (`agentview` is a camera every robosuite environment has). It sits on the sensor, next to `camera` (the name in the robot's own MJCF), because it is a fact about the robot that every robosuite scene of it shares: robosuite names the cameras it mounts on a robot after the robot's slot, such as `robot0_eye_in_hand` for the first robot's wrist camera.
    """
    mount_body: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) the camera is rigidly attached to, such as the hand for a wrist camera. Absent means a fixed camera placed by the scene.
    """
    mount_axis: MountAxis | None = None
    """
    Axis of `mount_body` the camera looks along. Absent: forward (+x) on a torso, head, pelvis or base body, and +z (the usual tool axis) on any other body. UR arms, for example, carry their tool along +y of wrist_3_link.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem] | None,
        Field(examples=[[0.15, 0.0, 1.2]], max_length=3, min_length=3),
    ] = None
    """
    Position in `mount_body`'s frame [m] x, y, z: of the camera (rgb and depth; absent: the default placement, see mount_axis) or of the site the scene creates for a lidar (absent: the body's origin). Needs `mount_body`.
    """
    fovy_deg: Annotated[StrictFloat, Field(gt=0.0, lt=180.0)] = 45.0
    """
    Vertical field of view [deg] of a camera the scene creates.
    """
    width: Annotated[StrictInt, Field(ge=16, le=4096)]
    """
    Image width [px], 16 to 4096.
    """
    height: Annotated[StrictInt, Field(ge=16, le=4096)]
    """
    Image height [px], 16 to 4096.
    """
    rate_hz: Annotated[StrictFloat, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000; the sim bridge's camera rate is a runtime setting.
    """
    frame_id: Annotated[
        StrictStr,
        Field(
            examples=["agentview_optical_frame"],
            pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$",
        ),
    ]
    """
    TF frame of the sensor's optical centre, copied into message headers.
    """
    vla_feature_key: Annotated[
        StrictStr | None,
        Field(
            examples=["observation.images.camera1"],
            pattern="^observation\\.images\\.[a-z][a-z0-9_]{0,62}$",
        ),
    ] = None
    """
    LeRobot-style observation key a vision-language-action policy expects this camera under, `observation.images.<slot>`. Only for rgb sensors. The slot (the part after the last dot) is what policies look frames up by.
    """
    device: Annotated[
        StrictStr | None,
        Field(
            examples=["0", "/dev/video2", "file:tests/fixtures/video/front.mp4"],
            pattern="^([0-9]{1,3}|/dev/[A-Za-z0-9_./-]{1,120}|file:[^\\u0000]{1,500})$",
        ),
    ] = None
    """
    Where a real robot's frames come from (`deploy real`; a simulation ignores it): a camera index (`0`), a V4L2 device path (`/dev/video0`) or a video file (`file:clips/front.mp4`, looped; relative to the working directory), read with OpenCV at `rate_hz` and scaled to width x height. Absent: the sensor is not published on the real robot unless `--camera NAME=DEVICE` names one. A device that cannot be opened stops the bring-up with one line.
    """


RangeMItem = TypeAliasType(
    "RangeMItem", Annotated[StrictFloat, Field(ge=0.0, le=1000.0)]
)


class DepthSensor(OpenralModel):
    """
    A depth camera; published as a depth image and a point cloud.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr,
        Field(examples=["agentview", "wrist"], pattern="^[a-z][a-z0-9_]{0,62}$"),
    ]
    """
    Sensor name, unique within the robot. Topics are derived from it (`/openral/cameras/<name>/image`).
    """
    kind: Literal["depth"]
    """
    `depth`: a depth camera (depth image and point cloud).
    """
    camera: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF camera the sensor renders from (rgb and depth). Defaults to the sensor name.
    """
    mount_body: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) the camera is rigidly attached to, such as the hand for a wrist camera. Absent means a fixed camera placed by the scene.
    """
    mount_axis: MountAxis | None = None
    """
    Axis of `mount_body` the camera looks along. Absent: forward (+x) on a torso, head, pelvis or base body, and +z (the usual tool axis) on any other body. UR arms, for example, carry their tool along +y of wrist_3_link.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem] | None,
        Field(examples=[[0.15, 0.0, 1.2]], max_length=3, min_length=3),
    ] = None
    """
    Position in `mount_body`'s frame [m] x, y, z: of the camera (rgb and depth; absent: the default placement, see mount_axis) or of the site the scene creates for a lidar (absent: the body's origin). Needs `mount_body`.
    """
    fovy_deg: Annotated[StrictFloat, Field(gt=0.0, lt=180.0)] = 45.0
    """
    Vertical field of view [deg] of a camera the scene creates.
    """
    width: Annotated[StrictInt, Field(ge=16, le=4096)]
    """
    Image width [px], 16 to 4096.
    """
    height: Annotated[StrictInt, Field(ge=16, le=4096)]
    """
    Image height [px], 16 to 4096.
    """
    rate_hz: Annotated[StrictFloat, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000; the sim bridge's camera rate is a runtime setting.
    """
    frame_id: Annotated[
        StrictStr,
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
    "AngleRangeDegItem", Annotated[StrictFloat, Field(ge=-360.0, le=360.0)]
)


class LidarSensor(OpenralModel):
    """
    A planar lidar: rays cast from an MJCF site (one of the model's, or one the scene creates on `mount_body`).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr,
        Field(examples=["agentview", "wrist"], pattern="^[a-z][a-z0-9_]{0,62}$"),
    ]
    """
    Sensor name, unique within the robot. Topics are derived from it (`/openral/cameras/<name>/image`).
    """
    kind: Literal["lidar"]
    """
    `lidar`: a planar laser scanner.
    """
    site: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    MJCF site the lidar's rays start from (lidar only): a site of the robot's (or its mobile base's) model, or, with `mount_body`, the name of the site a native scene creates there.
    """
    mount_body: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name, of the robot's or its mobile base's model) a native scene creates the lidar's `site` on, at `mount_position_m`, with the body's axes (the scan plane is the body's x-y plane), for a model that has no site where the lidar sits. Absent: `site` is a site of the model.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem] | None,
        Field(examples=[[0.15, 0.0, 1.2]], max_length=3, min_length=3),
    ] = None
    """
    Position in `mount_body`'s frame [m] x, y, z: of the camera (rgb and depth; absent: the default placement, see mount_axis) or of the site the scene creates for a lidar (absent: the body's origin). Needs `mount_body`.
    """
    width: Annotated[StrictInt, Field(ge=1, le=4096)]
    """
    Number of rays in one scan, 1 to 4096.
    """
    height: Annotated[StrictInt, Field(ge=1, le=1)]
    """
    Scan lines: always 1 (a planar lidar).
    """
    rate_hz: Annotated[StrictFloat, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000; the sim bridge's camera rate is a runtime setting.
    """
    frame_id: Annotated[
        StrictStr,
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


class ImuSensor(OpenralModel):
    """
    An IMU read from MuJoCo sensors at an MJCF site; published as `sensor_msgs/Imu`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr, Field(examples=["pelvis_imu"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Sensor name, unique within the robot. Its topic is derived from it (`/openral/imu/<name>`).
    """
    kind: Literal["imu"]
    """
    `imu`: an inertial measurement unit (orientation, angular velocity, linear acceleration).
    """
    site: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    MJCF site the sensor sits at: its frame is the sensor's frame. A site of the robot's (or its mobile base's) model, or, with `mount_body`, the name of the site a native scene creates there.
    """
    mount_body: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) a native scene creates the sensor's `site` on, at `mount_position_m`, with the body's axes, for a model that has no site where the sensor sits. Absent: `site` is a site of the model.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem] | None,
        Field(examples=[[0.0, 0.0, 0.05]], max_length=3, min_length=3),
    ] = None
    """
    Position of the created site in `mount_body`'s frame [m] x, y, z (absent: the body's origin). Needs `mount_body`.
    """
    accelerometer: Annotated[
        StrictStr | None,
        Field(
            examples=["imu-pelvis-linear-acceleration"],
            pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$",
        ),
    ] = None
    """
    MJCF `accelerometer` sensor at `site` this IMU reads its linear acceleration from [m/s², site frame; gravity included: +9.81 up at rest]. Absent: a native scene adds one at `site`.
    """
    gyro: Annotated[
        StrictStr | None,
        Field(
            examples=["imu-pelvis-angular-velocity"],
            pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$",
        ),
    ] = None
    """
    MJCF `gyro` sensor at `site` this IMU reads its angular velocity from [rad/s, site frame]. Absent: a native scene adds one at `site`.
    """
    orientation: Annotated[
        StrictStr | None,
        Field(examples=["imu-pelvis-quat"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"),
    ] = None
    """
    MJCF `framequat` sensor of `site` this IMU reads its orientation from (in the world frame). Absent: a native scene adds one at `site`.
    """
    rate_hz: Annotated[StrictFloat, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000. Under deploy sim a reading changes once per control step, so it is published at this rate or the control rate, whichever is lower.
    """
    frame_id: Annotated[
        StrictStr,
        Field(examples=["imu_link"], pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$"),
    ]
    """
    TF frame of the sensor (the site's frame), copied into message headers.
    """


class ForceTorqueSensor(OpenralModel):
    """
    A wrist or joint force-torque sensor read from MuJoCo `force` and `torque` sensors at an MJCF site; published as `geometry_msgs/WrenchStamped`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr, Field(examples=["wrist_ft"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Sensor name, unique within the robot. Its topic is derived from it (`/openral/wrench/<name>`).
    """
    kind: Literal["force_torque"]
    """
    `force_torque`: a six-axis force-torque sensor.
    """
    site: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    MJCF site the sensor sits at: its frame is the sensor's frame. A site of the robot's (or its mobile base's) model, or, with `mount_body`, the name of the site a native scene creates there.
    """
    mount_body: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) a native scene creates the sensor's `site` on, at `mount_position_m`, with the body's axes, for a model that has no site where the sensor sits. Absent: `site` is a site of the model.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem] | None,
        Field(examples=[[0.0, 0.0, 0.05]], max_length=3, min_length=3),
    ] = None
    """
    Position of the created site in `mount_body`'s frame [m] x, y, z (absent: the body's origin). Needs `mount_body`.
    """
    force: Annotated[
        StrictStr | None,
        Field(examples=["force"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"),
    ] = None
    """
    MJCF `force` sensor at `site` [N, site frame]: the force the parent body exerts on the subtree of the site's body. Absent: a native scene adds one at `site`.
    """
    torque: Annotated[
        StrictStr | None,
        Field(examples=["torque"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"),
    ] = None
    """
    MJCF `torque` sensor at `site` [N·m, site frame], as `force` for torque. Absent: a native scene adds one at `site`.
    """
    rate_hz: Annotated[StrictFloat, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000. Under deploy sim a reading changes once per control step, so it is published at this rate or the control rate, whichever is lower.
    """
    frame_id: Annotated[
        StrictStr,
        Field(examples=["imu_link"], pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$"),
    ]
    """
    TF frame of the sensor (the site's frame), copied into message headers.
    """


class PoseSensor(OpenralModel):
    """
    The world pose of an MJCF site, read from MuJoCo `framepos` and `framequat` sensors; published as `geometry_msgs/PoseStamped` in the `world` frame.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[
        StrictStr, Field(examples=["tool_pose"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Sensor name, unique within the robot. Its topic is derived from it (`/openral/pose/<name>`).
    """
    kind: Literal["pose"]
    """
    `pose`: the pose of a site in the world frame (a motion-capture marker, say).
    """
    site: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    MJCF site the sensor sits at: its frame is the sensor's frame. A site of the robot's (or its mobile base's) model, or, with `mount_body`, the name of the site a native scene creates there.
    """
    mount_body: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")
    ] = None
    """
    MJCF body (native name) a native scene creates the sensor's `site` on, at `mount_position_m`, with the body's axes, for a model that has no site where the sensor sits. Absent: `site` is a site of the model.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem] | None,
        Field(examples=[[0.0, 0.0, 0.05]], max_length=3, min_length=3),
    ] = None
    """
    Position of the created site in `mount_body`'s frame [m] x, y, z (absent: the body's origin). Needs `mount_body`.
    """
    position: Annotated[
        StrictStr | None,
        Field(examples=["tcp_pos"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"),
    ] = None
    """
    MJCF `framepos` sensor of `site` [m, world frame]. Absent: a native scene adds one.
    """
    orientation: Annotated[
        StrictStr | None,
        Field(examples=["tcp_quat"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"),
    ] = None
    """
    MJCF `framequat` sensor of `site` (world frame). Absent: a native scene adds one.
    """
    rate_hz: Annotated[StrictFloat, Field(ge=0.1, le=1000.0)]
    """
    Nominal publish rate [Hz] on a real robot, 0.1 to 1000. Under deploy sim a reading changes once per control step, so it is published at this rate or the control rate, whichever is lower.
    """
    frame_id: Annotated[
        StrictStr,
        Field(examples=["imu_link"], pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$"),
    ]
    """
    TF frame of the sensor (the site's frame), copied into message headers.
    """


MountQuatWxyzItem = TypeAliasType(
    "MountQuatWxyzItem", Annotated[StrictFloat, Field(ge=-1.0, le=1.0)]
)


class DriveKind(StrEnum):
    """
    How a mobile base moves. `holonomic`: forward (x), sideways (y) and about the vertical (yaw) independently, as on mecanum or omni wheels; simulated by two slide joints and a hinge, each driven by a velocity actuator.
    """

    holonomic = "holonomic"


class DriveAxes(OpenralModel):
    """
    One MJCF name per planar axis of a holonomic base.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    x: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    Forward, along the base frame's x axis.
    """
    y: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    Sideways, along the base frame's y axis (to the left).
    """
    yaw: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$")]
    """
    About the vertical (counter-clockwise seen from above).
    """


FrameName = TypeAliasType(
    "FrameName", Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$")]
)
"""
A TF frame id: starts with a letter; letters, digits, `_` and `/` (never a leading `/`, which tf2 refuses).
"""


UrdfJointName = TypeAliasType(
    "UrdfJointName",
    Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/-]{0,126}$")],
)
"""
A URDF joint name: starts with a letter; letters, digits, `_`, `/` and `-` (vendors write such names, e.g. ur_description's `base_link-base_link_inertia`).
"""


class JointLimits(OpenralModel):
    """
    A joint's velocity and effort limits.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    velocity_limit: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)]
    """
    Largest speed [rad/s or m/s].
    """
    effort_limit: Annotated[StrictFloat, Field(gt=0.0, le=1000000.0)]
    """
    Largest effort [N·m or N].
    """


class ExtraLink(OpenralModel):
    """
    A link rigidly fixed to another, with no body in the model.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$")]
    """
    The link's name.
    """
    parent: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$")]
    """
    The link it is fixed to (as `links` names it), or the base frame.
    """
    joint: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/-]{0,126}$")]
    """
    The name of the fixed joint from `parent` to it.
    """
    position_m: Annotated[list[StrictFloat], Field(max_length=3, min_length=3)] = [
        0.0,
        0.0,
        0.0,
    ]
    """
    Its origin in the parent's frame [m].
    """
    quat_wxyz: Annotated[list[StrictFloat], Field(max_length=4, min_length=4)] = [
        1.0,
        0.0,
        0.0,
        0.0,
    ]
    """
    Its orientation in the parent's frame (unit quaternion w, x, y, z; normalised on load).
    """
    children: list[FrameName] = []
    """
    Links of the parent re-hung from this one (their world poses unchanged).
    """


class TrajectoryRules(OpenralModel):
    """
    How a joint trajectory starts and when it has succeeded, as ros2_control's joint_trajectory_controller decides it with its `constraints` parameters. A client's own tolerances (FollowJointTrajectory goal) take precedence over `goal_time_s` and `stopped_velocity_tolerance`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    start_tolerance: Annotated[StrictFloat, Field(gt=0.0, le=1.0)] = 0.05
    """
    A trajectory whose first point (at time 0) is not where the joints are commanded is joined from where they are measured, if every joint is within this distance of it [rad or m]; farther, it is refused. Covers an arm that sags under gravity below its target, so a plan that starts where the arm is is never refused for it.
    """
    goal_time_s: Annotated[StrictFloat, Field(ge=0.0, le=600.0)] = 1.0
    """
    How long after a trajectory's last point the joints may take to come within the goal tolerance before the goal is aborted (GOAL_TOLERANCE_VIOLATED) [s], when the goal gives no `goal_time_tolerance`. 0: no limit (a goal tolerance that is never met keeps the goal running).
    """
    stopped_velocity_tolerance: Annotated[StrictFloat, Field(ge=0.0, le=10.0)] = 0.01
    """
    Largest joint speed at which a joint counts as stopped at the goal [rad/s or m/s], when the goal gives no velocity tolerance. 0: not checked.
    """


class MobileBase(OpenralModel):
    """
    A wheeled base the robot rides on: driven by planar velocity commands (cmd_vel) and reporting odometry. It sits on the robot, not inside `sim`, because its kind, limits, command timeout and frame names are facts about the robot that a real base driver and the ROS graph share; its MJCF fields tell a native scene how to build it: the base's own model, with the robot's model (`sim.mjcf_uri`) attached to `mount_body`, whose joint addresses keep their meaning in the robot's model. Needs `base: mobile`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    mjcf_uri: Annotated[
        StrictStr,
        Field(
            examples=[
                "pkg:robosuite/robosuite/models/assets/bases/omron_mobile_base.xml"
            ],
            pattern="^(file:|pkg:[A-Za-z0-9]([A-Za-z0-9._-]*[A-Za-z0-9])?/|robosuite:)[A-Za-z0-9_./-]+$",
        ),
    ]
    """
    Where the base's MJCF model is found, resolved offline like `sim.mjcf_uri` (the same schemes `file:` and `pkg:` (`robosuite:` deprecated), and the same confinement: the model and every file it loads stay in the robot's folder or in the installed distribution).
    """
    mount_body: Annotated[
        StrictStr,
        Field(examples=["support"], pattern="^[A-Za-z][A-Za-z0-9_/.-]{0,126}$"),
    ]
    """
    Body of the base's model the robot's model is attached to: the robot's root bodies become its children.
    """
    mount_position_m: Annotated[
        list[MountPositionMItem], Field(max_length=3, min_length=3)
    ] = [0.0, 0.0, 0.0]
    """
    Position of the robot model's world frame in `mount_body`'s frame [m] x, y, z.
    """
    mount_quat_wxyz: Annotated[
        list[MountQuatWxyzItem], Field(max_length=4, min_length=4)
    ] = [1.0, 0.0, 0.0, 0.0]
    """
    Orientation of the robot model's world frame in `mount_body`'s frame, a quaternion w, x, y, z (normalised by MuJoCo; [1, 0, 0, 0] keeps the axes).
    """
    drive: DriveKind
    """
    How the base moves (see DriveKind).
    """
    joints: Annotated[
        DriveAxes,
        Field(
            examples=[
                {
                    "x": "joint_mobile_forward",
                    "y": "joint_mobile_side",
                    "yaw": "joint_mobile_yaw",
                }
            ]
        ),
    ]
    """
    MJCF joints of the base's model (native names) that move it in the plane. A `holonomic` drive needs slide joints `x` and `y` followed by a hinge `yaw` about the vertical, all on the base's root body (a child of the world), so the slides move along the axes of the frame the base is placed in.
    """
    actuators: Annotated[
        DriveAxes,
        Field(
            examples=[
                {
                    "x": "actuator_mobile_forward",
                    "y": "actuator_mobile_side",
                    "yaw": "actuator_mobile_yaw",
                }
            ]
        ),
    ]
    """
    MJCF velocity actuators of the base's model (native names), one driving each of `joints`: ctrl is the joint's velocity [m/s, rad/s].
    """
    max_linear_velocity_m_s: Annotated[
        StrictFloat, Field(examples=[0.5], gt=0.0, le=10.0)
    ]
    """
    Fastest planar speed of the base [m/s]: a command whose (vx, vy) is longer is scaled down to it, keeping its direction.
    """
    max_angular_velocity_rad_s: Annotated[
        StrictFloat, Field(examples=[1.0], gt=0.0, le=20.0)
    ]
    """
    Fastest turn about the vertical [rad/s]: a command's wz is clamped to it.
    """
    max_linear_acceleration_m_s2: Annotated[
        StrictFloat, Field(examples=[1.0], gt=0.0, le=50.0)
    ]
    """
    Largest change of the planar velocity [m/s²]: the velocity in force moves towards the command by at most this much per second, speeding up and slowing down.
    """
    max_angular_acceleration_rad_s2: Annotated[
        StrictFloat, Field(examples=[2.0], gt=0.0, le=100.0)
    ]
    """
    Largest change of the turn rate [rad/s²], as for max_linear_acceleration_m_s2.
    """
    command_timeout_s: Annotated[StrictFloat, Field(gt=0.0, le=60.0)] = 0.5
    """
    Time [s] (simulated time in a scene) after the last velocity command at which the base is told to stop (it slows down at its acceleration limits), so a client that dies never leaves it driving.
    """
    odom_frame: Annotated[
        StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$")
    ] = "odom"
    """
    TF frame of the odometry (REP 105): fixed in the world, where the base's frame was when the scene was reset.
    """
    base_frame: Annotated[
        StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$")
    ] = "base_link"
    """
    TF frame of the base (REP 105), the child frame of the odometry: on the floor plane at the yaw joint's axis, turning with the base; velocity commands are given in it.
    """


class Frames(OpenralModel):
    """
    The frames of `/tf` that are not bodies of the model, and the names the robot's links and joints take in ROS. Every body of the robot is a link named as in its MJCF unless `links` renames it (to the vendor's URDF names, which MoveIt configurations and SRDFs use); `world` and `base` name the fixed frame of the simulated world and the robot's base frame, the root of its URDF and the frame depth clouds are given in. A robot with a `mobile_base` names its base frame there (`mobile_base.base_frame`, beside `odom_frame`), not here.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    world: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$")] = (
        "world"
    )
    """
    The fixed frame of the simulated world (MuJoCo's world frame): the parent of the base frame (or of the odometry frame) and of cameras fixed in the scene.
    """
    base: Annotated[
        StrictStr,
        Field(examples=["base_link"], pattern="^[A-Za-z][A-Za-z0-9_/]{0,126}$"),
    ] = "base_link"
    """
    The robot's base frame, at its root body (the world's child that carries its first joint), turning and moving with it. It must not be the name of another body of the model; it may be the root body's own name (then that body is the base frame).
    """
    links: Annotated[
        dict[MjcfName, FrameName],
        Field(examples=[{"link0": "panda_link0", "hand": "panda_hand"}]),
    ] = {}
    """
    Link names for bodies of the robot: MJCF body name → link name. A body not listed keeps its MJCF name. TF, the URDF, the SRDF and every frame_id (sensors mounted on a body, the TCP's parent) follow.
    """
    joints: Annotated[
        dict[FrameName, UrdfJointName],
        Field(
            examples=[
                {
                    "finger_joint2": "panda_finger_joint2",
                    "panda_hand": "panda_hand_joint",
                }
            ]
        ),
    ] = {}
    """
    Names of the joints the manifest does not list: an MJCF joint's name (a finger that mimics another) or a link's name (as `links` names it) for the fixed joint into that link → joint name. Default: the MJCF name; the fixed joint into link L is `L_fixed`. Manifest joints keep the manifest's names.
    """
    joint_limits: Annotated[
        dict[MjcfName, JointLimits],
        Field(
            examples=[
                {"joint_torso_height": {"velocity_limit": 0.1, "effort_limit": 1000.0}}
            ],
            validate_default=True,
        ),
    ] = {}
    """
    Velocity and effort limits of joints the manifest does not list (a passive or held joint, such as a mobile base's torso slide), by MJCF joint name, for the URDF. Default: no velocity limit (0, which MoveIt reads as a joint that cannot move) and the effort of the actuator driving the joint. A mimic joint takes its leader's limits.
    """
    extra_links: Annotated[list[ExtraLink], Field(validate_default=True)] = []
    """
    Frames with no body of their own that the vendor's URDF has (the Panda's flange `panda_link8`): each a link fixed to `parent`, optionally taking over some of the parent's children (which keep their poses in the world).
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
        StrictStr,
        Field(examples=["franka_panda", "ur5e"], pattern="^[a-z][a-z0-9_]{1,62}$"),
    ]
    """
    Robot id: lower-case snake case, equal to the name of the folder under robots/ that holds this file. Used on the command line (`openral robot show <name>`) and as the default ROS namespace.
    """
    display_name: Annotated[
        StrictStr, Field(examples=["Franka Emika Panda"], max_length=80, min_length=1)
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
        list[
            RgbSensor
            | DepthSensor
            | LidarSensor
            | ImuSensor
            | ForceTorqueSensor
            | PoseSensor
        ],
        Field(max_length=32, validate_default=True),
    ] = []
    """
    Sensors the robot carries or that its scenes provide for it (cameras, depth cameras, lidars). Each becomes a ROS topic under deploy sim.
    """
    base: Base
    """
    How the robot stands: `fixed` is bolted to the world (or to a table); `mobile` drives around (odometry and cmd_vel apply): on a wheeled base described by `mobile_base`, or, with `sim.floating_base`, on its own legs.
    """
    mobile_base: MobileBase | None = None
    """
    The wheeled base the robot rides on (only with `base: mobile`); see MobileBase.
    """
    frames: Frames | None = None
    """
    Names of the ROS frames the graph adds to the model's bodies (see Frames). Absent: `world` and `base_link`.
    """
    trajectory: TrajectoryRules | None = None
    """
    How joint trajectories (the FollowJointTrajectory action and `/openral/joint_trajectory`) are joined and judged for this robot (see TrajectoryRules). Absent: every default.
    """
    sim: sim_schema.SimDescription | None = None
    """
    MuJoCo wiring: where the model comes from and how joints map to qpos, qvel and actuators. Absent for robots that have no simulation model.
    """
    real: real_schema.RealDescription | None = None
    """
    How the physical robot is driven (driver, control rate, E-stop and shutdown behaviour, the servo bus); see RealDescription. Absent: the robot has no real driver and `build_hal(mode="real")` refuses it.
    """
