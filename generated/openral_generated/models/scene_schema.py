# GENERATED from schema/ by `just schema-export` -- do not edit.

from __future__ import annotations

from pydantic import ConfigDict, Field, StrictBool, StrictFloat, StrictInt, StrictStr
from typing import Annotated, Literal
from openral_base import OpenralModel
from typing_extensions import TypeAliasType
from enum import StrEnum


PositionMItem = TypeAliasType(
    "PositionMItem", Annotated[StrictFloat, Field(ge=-100.0, le=100.0)]
)


class BasePose(OpenralModel):
    """
    Pose of the robot base in the world frame.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    position_m: Annotated[list[PositionMItem], Field(max_length=3, min_length=3)] = [
        0.0,
        0.0,
        0.0,
    ]
    """
    Base position x, y, z [m].
    """
    yaw_deg: Annotated[StrictFloat, Field(ge=-360.0, le=360.0)] = 0.0
    """
    Base rotation about the world z axis [deg].
    """
    weld: StrictBool = False
    """
    Floating-base robots only: hold the root body at this pose with a weld constraint, as a gantry or a stand holds a humanoid that has no balance controller. The free joint stays in the model, so no joint address changes. An error on a fixed-base robot.
    """


class Observation(OpenralModel):
    """
    Rendered image size shared by every camera of the scene.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    width: Annotated[StrictInt, Field(ge=16, le=4096)]
    """
    Image width [px], 16 to 4096.
    """
    height: Annotated[StrictInt, Field(ge=16, le=4096)]
    """
    Image height [px], 16 to 4096.
    """


class Shape(StrEnum):
    """
    Primitive geometry.
    """

    box = "box"
    sphere = "sphere"
    cylinder = "cylinder"


SizeMItem = TypeAliasType("SizeMItem", Annotated[StrictFloat, Field(gt=0.0, le=10.0)])


RgbaItem = TypeAliasType("RgbaItem", Annotated[StrictFloat, Field(ge=0.0, le=1.0)])


class SceneObject(OpenralModel):
    """
    A simple primitive object placed in a native scene.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    name: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    Body name of the object in the composed model.
    """
    shape: Shape
    """
    Primitive geometry.
    """
    size_m: Annotated[list[SizeMItem], Field(max_length=3, min_length=1)]
    """
    MuJoCo geom size [m]: half-extents (box, 3 values), radius (sphere, 1) or radius and half-height (cylinder, 2).
    """
    position_m: Annotated[list[PositionMItem], Field(max_length=3, min_length=3)]
    """
    Initial position x, y, z [m] in the world frame.
    """
    rgba: Annotated[list[RgbaItem], Field(max_length=4, min_length=4)] = [
        0.8,
        0.2,
        0.2,
        1.0,
    ]
    """
    Colour, each channel in [0, 1].
    """
    mass_kg: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)] = 0.1
    """
    Mass [kg].
    """
    free: StrictBool = True
    """
    True: the object is loose (free joint); false: fixed to the world.
    """


class SceneOptions(OpenralModel):
    """
    Backend options. Each backend reads the fields that apply to it and ignores none silently: a field another backend owns is an error when the scene is built.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    control_freq_hz: Annotated[StrictFloat, Field(ge=1.0, le=2000.0)] = 20.0
    """
    How often an action is applied [Hz], 1 to 2000; each env.step advances 1/control_freq_hz seconds of physics.
    """
    state_rate_hz: Annotated[StrictFloat, Field(ge=1.0, le=1000.0)] = 100.0
    """
    How often the physics state advances and is published under `deploy sim` [Hz] (native only), 1 to 1000, at least control_freq_hz: each control period is stepped in parts of about 1/state_rate_hz (a whole number of physics steps that divides the period), and /joint_states, /tf, /odom and the TCP pose carry every part's new state, as a robot's driver does at its update rate. Actions keep control_freq_hz.
    """
    horizon: Annotated[StrictInt | None, Field(ge=1, le=100000000)] = None
    """
    Control steps after which an episode is truncated: gymnasium's `truncated` and the `max_episode_steps` of the scene's registered env id, and a sweep's step limit unless `--steps` sets one (left out: 300). `deploy sim` runs on past it (its world never resets by itself). robosuite: its own default of 1000 when left out.
    """
    controller: Annotated[
        StrictStr | None, Field(pattern="^[A-Za-z][A-Za-z0-9_]{0,62}$")
    ] = None
    """
    robosuite controller config name (robosuite only), such as `BASIC`.
    """
    table_height_m: Annotated[StrictFloat | None, Field(gt=0.0, le=3.0)] = None
    """
    Height of the table top [m] (native tabletop only).
    """
    objects: Annotated[list[SceneObject] | None, Field(max_length=64)] = None
    """
    Objects of a native scene: loose props (on the table), or, with `free: false`, bodies fixed to the world such as walls and furniture (native only).
    """


class Backend(StrEnum):
    """
    Simulator backend that owns physics and rendering: `native` (a scene composed with mujoco.MjSpec around the robot's own MJCF) or `robosuite` (a robosuite environment).
    """

    native = "native"
    robosuite = "robosuite"


Camera = TypeAliasType(
    "Camera", Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
)


class NativeAssets(StrEnum):
    """
    A layout the native backend builds around the robot: `tabletop` (floor, lights and a table) or `floor` (floor and lights only, for models that bring their own table).
    """

    tabletop = "tabletop"
    floor = "floor"


RobosuiteEnvironment = TypeAliasType(
    "RobosuiteEnvironment",
    Annotated[StrictStr, Field(pattern="^[A-Z][A-Za-z0-9]{0,62}$")],
)
"""
A robosuite environment name, exactly as robosuite spells it (`Lift`, `PickPlaceCan`); checked against the installed robosuite when the scene is built.
"""


PositionMinMItem = TypeAliasType(
    "PositionMinMItem", Annotated[StrictFloat, Field(ge=-1.0, le=1.0)]
)


PositionMaxMItem = TypeAliasType(
    "PositionMaxMItem", Annotated[StrictFloat, Field(ge=-1.0, le=1.0)]
)


YawDegItem = TypeAliasType(
    "YawDegItem", Annotated[StrictFloat, Field(ge=-360.0, le=360.0)]
)


RgbaItem1Item = TypeAliasType(
    "RgbaItem1Item", Annotated[StrictFloat, Field(ge=0.0, le=1.0)]
)


RgbaItem1 = TypeAliasType(
    "RgbaItem1", Annotated[list[RgbaItem1Item], Field(max_length=4, min_length=4)]
)


class ObjectRandomization(OpenralModel):
    """
    Seeded ranges for one object's start: where it lies, how it is turned, its colour.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    position_min_m: Annotated[
        list[PositionMinMItem] | None, Field(max_length=3, min_length=3)
    ] = None
    """
    Lowest offset x, y, z [m] added to the object's `position_m` (uniform per axis).
    """
    position_max_m: Annotated[
        list[PositionMaxMItem] | None, Field(max_length=3, min_length=3)
    ] = None
    """
    Highest offset x, y, z [m] added to the object's `position_m`; each at least `position_min_m`'s.
    """
    yaw_deg: Annotated[
        list[YawDegItem] | None,
        Field(examples=[[-180.0, 180.0]], max_length=2, min_length=2),
    ] = None
    """
    Range of the object's turn about the world z axis [deg] (uniform).
    """
    rgba: Annotated[list[RgbaItem1] | None, Field(max_length=64, min_length=1)] = None
    """
    Colours to choose from, one per episode (uniform); each channel in [0, 1].
    """


LightIntensityScaleItem = TypeAliasType(
    "LightIntensityScaleItem", Annotated[StrictFloat, Field(ge=0.0, le=10.0)]
)


class Randomization(OpenralModel):
    """
    Seeded ranges an episode's start is drawn from (a native scene). The episode's seed alone decides every draw: the same seed gives the same episode in `openral sim run`, `deploy sim` and `openral sim sweep`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    objects: Annotated[list[ObjectRandomization] | None, Field(max_length=256)] = None
    """
    Per object: position offset, yaw and colour ranges.
    """
    light_intensity_scale: Annotated[
        list[LightIntensityScaleItem] | None,
        Field(examples=[[0.8, 1.2]], max_length=2, min_length=2),
    ] = None
    """
    Range of one factor scaling every scene light's diffuse intensity (uniform).
    """
    light_direction_deg: Annotated[StrictFloat | None, Field(ge=0.0, le=90.0)] = None
    """
    Largest tilt of each directional light's direction [deg] (uniform in a cone).
    """
    camera_position_m: Annotated[StrictFloat | None, Field(ge=0.0, le=1.0)] = None
    """
    Largest offset of each fixed scene camera's position along each axis [m] (uniform).
    """
    camera_angle_deg: Annotated[StrictFloat | None, Field(ge=0.0, le=45.0)] = None
    """
    Largest turn of each fixed scene camera about a random axis [deg] (uniform).
    """
    joint_noise: Annotated[StrictFloat | None, Field(ge=0.0, le=0.5)] = None
    """
    Largest offset added to each arm joint's start position [rad or m] (uniform ±).
    """


class ObjectAbove(OpenralModel):
    """
    The object's centre is above a height (lifted).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["object_above"]
    """
    `object_above`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    for_s: Annotated[StrictFloat, Field(ge=0.0, le=3600.0)] = 0.0
    """
    How long the predicate must hold without a break [s] (0: at one control step).
    """
    z_m: Annotated[StrictFloat, Field(ge=-100.0, le=100.0)]
    """
    Height in the world frame [m] the object's centre must be above.
    """


MinMItem = TypeAliasType("MinMItem", Annotated[StrictFloat, Field(ge=-100.0, le=100.0)])


MaxMItem = TypeAliasType("MaxMItem", Annotated[StrictFloat, Field(ge=-100.0, le=100.0)])


class ObjectInRegion(OpenralModel):
    """
    The object's centre is inside an axis-aligned box of the world (placed).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["object_in_region"]
    """
    `object_in_region`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    for_s: Annotated[StrictFloat, Field(ge=0.0, le=3600.0)] = 0.0
    """
    How long the predicate must hold without a break [s] (0: at one control step).
    """
    min_m: Annotated[list[MinMItem], Field(max_length=3, min_length=3)]
    """
    The box's lowest corner x, y, z [m], world frame.
    """
    max_m: Annotated[list[MaxMItem], Field(max_length=3, min_length=3)]
    """
    The box's highest corner x, y, z [m], world frame.
    """


class GripperHolds(OpenralModel):
    """
    Every finger of the robot's gripper touches the object (held between the fingers).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["gripper_holds"]
    """
    `gripper_holds`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    for_s: Annotated[StrictFloat, Field(ge=0.0, le=3600.0)] = 0.0
    """
    How long the predicate must hold without a break [s] (0: at one control step).
    """


class ReachReward(OpenralModel):
    """
    The tool centre point (`sim.tcp`) near the object: 1 - tanh(scale_per_m x the distance from the TCP to the object's centre).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["reach"]
    """
    `reach`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    weight: Annotated[StrictFloat, Field(gt=0.0, le=100.0)] = 1.0
    """
    The term's share of the dense reward (terms are summed with these weights, then divided by their sum).
    """
    scale_per_m: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)] = 10.0
    """
    How fast the term falls off with distance [1/m]: the term is 1 - tanh(scale_per_m x distance) (robosuite's Lift uses 10).
    """


class GraspReward(OpenralModel):
    """
    The object held: 1 while every finger of the robot's gripper touches it (as `gripper_holds`), else 0.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["grasp"]
    """
    `grasp`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    weight: Annotated[StrictFloat, Field(gt=0.0, le=100.0)] = 1.0
    """
    The term's share of the dense reward (terms are summed with these weights, then divided by their sum).
    """


class LiftReward(OpenralModel):
    """
    The object raised while held: the fraction of the way from its height at reset to `z_m` (0 to 1), counted only while every finger touches it.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["lift"]
    """
    `lift`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    weight: Annotated[StrictFloat, Field(gt=0.0, le=100.0)] = 1.0
    """
    The term's share of the dense reward (terms are summed with these weights, then divided by their sum).
    """
    z_m: Annotated[StrictFloat, Field(ge=-100.0, le=100.0)]
    """
    The height in the world frame [m] at which the term is 1 (the height `object_above` asks for).
    """


class PlaceReward(OpenralModel):
    """
    The object brought into a box while held: 1 - tanh(scale_per_m x its centre's distance to the box) (1 inside), counted only while every finger touches it.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    kind: Literal["place"]
    """
    `place`.
    """
    object: Annotated[StrictStr, Field(pattern="^[a-z][a-z0-9_]{0,62}$")]
    """
    An object of `scene.options.objects`, by its `name`.
    """
    weight: Annotated[StrictFloat, Field(gt=0.0, le=100.0)] = 1.0
    """
    The term's share of the dense reward (terms are summed with these weights, then divided by their sum).
    """
    min_m: Annotated[list[MinMItem], Field(max_length=3, min_length=3)]
    """
    The box's lowest corner x, y, z [m], world frame.
    """
    max_m: Annotated[list[MaxMItem], Field(max_length=3, min_length=3)]
    """
    The box's highest corner x, y, z [m], world frame.
    """
    scale_per_m: Annotated[StrictFloat, Field(gt=0.0, le=1000.0)] = 10.0
    """
    How fast the term falls off with distance [1/m]: the term is 1 - tanh(scale_per_m x distance) (robosuite's Lift uses 10).
    """


class TaskReward(OpenralModel):
    """
    The scene's reward for training. Sparse: 1 at a control step where `success` holds, else 0 (nothing to declare). Dense: the weighted mean of `dense`'s terms, each between 0 and 1, and 1 at a step where `success` holds, so success is always worth the most (as robosuite's Lift and ManiSkill's PickCube stage reach, grasp and lift). A gymnasium env picks one with `reward_mode`.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    dense: Annotated[
        list[ReachReward | GraspReward | LiftReward | PlaceReward],
        Field(max_length=16, min_length=1),
    ]
    """
    The dense reward's terms, in the order a task meets them (reach, grasp, then lift or place).
    """


class SceneSpec(OpenralModel):
    """
    Scene identity, backend, assets, image size and cameras.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    id: Annotated[
        StrictStr, Field(examples=["tabletop"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    Scene id, used in logs and output folder names.
    """
    backend: Backend
    """
    Simulator backend that owns physics and rendering: `native` (a scene composed with mujoco.MjSpec around the robot's own MJCF) or `robosuite` (a robosuite environment).
    """
    assets: NativeAssets | RobosuiteEnvironment = NativeAssets.tabletop
    """
    What the backend builds the scene from: for `native` one of the built-in layouts (see NativeAssets), for `robosuite` the environment name (see RobosuiteEnvironment). When left out, a native scene is a `tabletop` and a robosuite scene names its environment by `id`.
    """
    observation: Observation
    """
    Rendered image size.
    """
    cameras: Annotated[list[Camera], Field(max_length=16)]
    """
    Cameras to render, by sensor name of the robot's manifest.
    """
    options: SceneOptions | None = None
    """
    Backend options.
    """


class DeployScene(OpenralModel):
    """
    A deploy scene: the file passed as `--config` to `openral sim run` and `openral deploy sim`. It names the robot, the simulator backend that owns physics and pixels, the cameras to render and where the robot stands.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    schema_version: Literal["0.1"]
    """
    Version of this contract. Only "0.1" exists.
    """
    robot_id: Annotated[
        StrictStr | None,
        Field(examples=["franka_panda"], pattern="^[a-z][a-z0-9_]{1,62}$"),
    ] = None
    """
    Id of the robot (a folder under robots/) placed in the scene. A scene file under robots/<id>/scenes/ belongs to robot <id>: there robot_id may be left out (it is then <id>) and any other value is an error. Elsewhere it names the robot; left out, the caller must supply one (`openral sim run --robot`), else the scene is refused.
    """
    seed: Annotated[StrictInt, Field(ge=0, le=2147483647)] = 0
    """
    Seed for the backend's episode reset (object placement, noise). The same seed gives the same first frame.
    """
    base_pose: BasePose | None = None
    """
    Where the robot's base is placed in the world. A mobile base stands on the floor there, and its odometry starts there.
    """
    scene: SceneSpec
    """
    The scene itself.
    """
    randomization: Randomization | None = None
    success: Annotated[
        list[ObjectAbove | ObjectInRegion | GripperHolds] | None,
        Field(max_length=32, min_length=1),
    ] = None
    """
    What success means in this scene: every predicate holds (AND). An episode ends on success or at its step limit.
    """
    reward: TaskReward | None = None
    task: Annotated[
        StrictStr | None,
        Field(examples=["lift the red cube"], max_length=300, min_length=1),
    ] = None
    """
    What the robot is asked to do in this scene, in words (the task text of a LeRobot dataset exported from its episodes, and of a language-conditioned policy). Left out: the scene's id.
    """
