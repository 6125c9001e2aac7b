# GENERATED from schema/ by `just schema-export` -- do not edit.

from __future__ import annotations

from enum import StrEnum
from pydantic import (
    ConfigDict,
    Field,
    StrictBool,
    StrictFloat,
    StrictInt,
    StrictStr,
    StringConstraints,
)
from typing import Annotated
from openral_base import OpenralModel
from typing_extensions import TypeAliasType


class Driver(StrEnum):
    """
    Which driver reaches the hardware. `feetech`: a bus of Feetech STS serial servos, one per joint, through feetech-servo-sdk (LeRobot's SO-100 and SO-101 arms); its wiring is `feetech`. `ros2_control`: the robot's own ROS 2 driver (franka_ros2, ur_robot_driver, xarm_ros2, ...) with a joint_state_broadcaster and a joint_trajectory_controller, reached over ROS 2 in the namespace given on the command line (`--transport ros2_control:<namespace>`); its names are `ros2_control`.
    """

    feetech = "feetech"
    ros2_control = "ros2_control"


class Estop(StrEnum):
    """
    What the E-stop does to the motors, within one control period: `hold` keeps torque on and holds the last measured position (the arm stays where it is); `torque_off` cuts torque (the arm goes limp and falls under gravity unless it rests).
    """

    hold = "hold"
    torque_off = "torque_off"


class Shutdown(StrEnum):
    """
    The motors' torque state after the driver stops (Ctrl-C, SIGTERM, disconnect): first every joint holds its last measured position, then `hold` leaves torque on (the servos keep holding with nothing watching them) or `torque_off` releases it (LeRobot's choice: rest the arm first, it falls).
    """

    hold = "hold"
    torque_off = "torque_off"


class ServoModel(StrEnum):
    """
    The servo on every joint (its control table, model number and resolution). `sts3215` (model number 777) and `sts3250` (2825): 4096 steps per turn.
    """

    sts3215 = "sts3215"
    sts3250 = "sts3250"


class FeetechMotor(OpenralModel):
    """
    The servo that drives one joint.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    joint: Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_]{0,62}$")]
    """
    The manifest joint this servo drives.
    """
    id: Annotated[StrictInt, Field(ge=0, le=252)]
    """
    The servo's bus id, 0 to 252 (253 is reserved, 254 is the broadcast id).
    """


class FeetechCalibration(OpenralModel):
    """
    Where an arm's calibration lives: `<dir>/<arm id>.json` in LeRobot's format (`id`, `drive_mode`, `homing_offset`, `range_min`, `range_max` per motor), where `<dir>` is LeRobot's calibration folder for this robot type (`$HF_LEROBOT_CALIBRATION/robots/<lerobot_robot_type>`, `~/.cache/huggingface/lerobot/calibration/robots/<lerobot_robot_type>` by default) and the arm id is given on the command line (`--arm-id`, LeRobot's `--robot.id`). So an arm calibrated with LeRobot is used as it is, and `openral robot calibrate` writes a file LeRobot reads.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    lerobot_robot_type: Annotated[
        StrictStr, Field(examples=["so101_follower"], pattern="^[a-z][a-z0-9_]{0,62}$")
    ]
    """
    LeRobot's robot type whose calibration folder holds this arm's file.
    """


class FeetechSettings(OpenralModel):
    """
    Servo registers by name, each a value the register holds (0 to 65535; a 1-byte register 0 to 255).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    Return_Delay_Time: Annotated[StrictInt | None, Field(ge=0, le=254)] = None
    """
    Delay before a servo answers [2 µs units]; 0 answers at once (the factory value 250 costs 0.5 ms per servo and read).
    """
    Acceleration: Annotated[StrictInt | None, Field(ge=0, le=254)] = None
    """
    Acceleration of the servo's own motion profile [100 steps/s²]; 0 is no profile.
    """
    P_Coefficient: Annotated[StrictInt | None, Field(ge=0, le=255)] = None
    """
    Position loop proportional gain (factory 32; LeRobot 16 to stop shaking).
    """
    I_Coefficient: Annotated[StrictInt | None, Field(ge=0, le=255)] = None
    """
    Position loop integral gain.
    """
    D_Coefficient: Annotated[StrictInt | None, Field(ge=0, le=255)] = None
    """
    Position loop derivative gain.
    """
    Max_Torque_Limit: Annotated[StrictInt | None, Field(ge=0, le=1000)] = None
    """
    Torque ceiling stored in EEPROM [0.1 % of stall torque], 0 to 1000.
    """
    Protection_Current: Annotated[StrictInt | None, Field(ge=0, le=2047)] = None
    """
    Current above which the servo protects itself [6.5 mA units], 0 to 2047.
    """
    Overload_Torque: Annotated[StrictInt | None, Field(ge=0, le=100)] = None
    """
    Torque the servo falls back to after an overload [%], 0 to 100.
    """


class CommandInterface(StrEnum):
    """
    How actions reach the controller: `topic` streams one-point trajectories (trajectory_msgs/JointTrajectory, `time_from_start` one control period) at the control rate, each replacing the last, as teleoperation does; `action` sends each as a FollowJointTrajectory goal (one goal in flight; a new one pre-empts it).
    """

    topic = "topic"
    action = "action"


JointNamesAdditionalProperty = TypeAliasType(
    "JointNamesAdditionalProperty",
    Annotated[StrictStr, Field(pattern="^[A-Za-z][A-Za-z0-9_/-]{0,126}$")],
)


class FeetechBus(OpenralModel):
    """
    A half-duplex serial bus of Feetech STS servos, one servo per manifest joint, in position mode. The port is not a fact about the robot and is given on the command line (`--transport /dev/ttyACM0`).
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    baud_rate: Annotated[StrictInt, Field(ge=19200, le=1000000)] = 1000000
    """
    Bus speed [bit/s]: one of the rates STS servos offer (1000000, 500000, 250000, 128000, 115200, 57600, 38400, 19200). LeRobot's arms run at 1,000,000.
    """
    protocol: Annotated[StrictInt, Field(ge=0, le=1)] = 0
    """
    Feetech protocol end: 0 for STS/SMS servos (little-endian words, Sync Read), 1 for SCS servos. The driver reads every joint in one Sync Read, so it needs 0.
    """
    servo_model: ServoModel
    """
    The servo on every joint (its control table, model number and resolution). `sts3215` (model number 777) and `sts3250` (2825): 4096 steps per turn.
    """
    motors: Annotated[list[FeetechMotor], Field(max_length=64, min_length=1)]
    """
    One motor per manifest joint, the gripper included: the joint and the servo's bus id.
    """
    reply_timeout_ms: Annotated[StrictFloat, Field(ge=1.0, le=100.0)] = 6.0
    """
    How long the driver waits for one servo's status reply, beyond the reply's own wire time, before it counts the servo as silent [ms]. A silent servo latches the E-stop: keep the control period plus this below two control periods (100 Hz: 6 ms latches within 17 ms). A servo answers within a millisecond; the rest is room for the adapter and for the operating system passing the bytes on when the machine is busy.
    """
    calibration: FeetechCalibration | None = None
    """
    Which calibration file the driver reads; see FeetechCalibration.
    """
    settings: FeetechSettings | None = None
    """
    Registers written to every servo when the driver connects, by the control table's names (only values that differ from what the servo holds are written, so EEPROM is spared). LeRobot's arms: Return_Delay_Time 0, Acceleration 254, P_Coefficient 16, I_Coefficient 0, D_Coefficient 32.
    """
    joint_settings: (
        dict[
            Annotated[
                str,
                StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True),
            ],
            FeetechSettings,
        ]
        | None
    ) = None
    """
    Per-joint registers written after `settings` (the same names), keyed by joint: LeRobot limits its grippers' torque (Max_Torque_Limit 500, Protection_Current 250, Overload_Torque 25).
    """


class Ros2ControlDriver(OpenralModel):
    """
    Where a ros2_control robot driver takes commands and gives its state, relative to its namespace (the namespace is not a fact about the robot: `--transport ros2_control:<namespace>`). The defaults are ros2_control's own names, which franka_ros2 and ur_robot_driver keep.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    joint_state_topic: Annotated[
        StrictStr,
        Field(
            max_length=200,
            pattern="^[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*){0,7}$",
            title="RosRelativeName",
        ),
    ] = "joint_states"
    """
    The joint_state_broadcaster's topic (sensor_msgs/JointState). Its stamps must be fresh: a stream that stops for two control periods latches the E-stop.
    """
    controller: Annotated[
        StrictStr,
        Field(
            max_length=200,
            pattern="^[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*){0,7}$",
            title="RosRelativeName",
        ),
    ] = "joint_trajectory_controller"
    """
    The joint_trajectory_controller over the manifest's arm joints: commands go to `<controller>/joint_trajectory` (topic) or `<controller>/follow_joint_trajectory` (action).
    """
    command_interface: CommandInterface = CommandInterface.topic
    """
    How actions reach the controller: `topic` streams one-point trajectories (trajectory_msgs/JointTrajectory, `time_from_start` one control period) at the control rate, each replacing the last, as teleoperation does; `action` sends each as a FollowJointTrajectory goal (one goal in flight; a new one pre-empts it).
    """
    gripper_action: Annotated[
        StrictStr | None,
        Field(
            examples=["gripper_controller/gripper_cmd"],
            max_length=200,
            pattern="^[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*){0,7}$",
            title="RosRelativeName",
        ),
    ] = None
    """
    The gripper's control_msgs/GripperCommand action (a parallel_gripper_action_controller or gripper_action_controller). Absent: the robot's gripper joints, if any, go through the trajectory controller with the arm.
    """
    joint_names: dict[
        Annotated[
            str, StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,62}$", strict=True)
        ],
        JointNamesAdditionalProperty,
    ] = {}
    """
    The driver's joint names where they differ from the manifest's: manifest joint → driver joint. A joint not listed keeps its manifest name.
    """


class RealDescription(OpenralModel):
    """
    How the physical robot is driven: by `openral deploy real`, `openral robot calibrate` and `build_hal(mode="real")`. The safety envelope is the manifest's own (joint limits, velocity limits, E-stop); this section says which driver reaches the hardware, how often it reads and writes it, and what the E-stop and a shutdown do to it. Absent: the robot has no real driver.
    """

    model_config = ConfigDict(
        extra="forbid",
    )
    driver: Driver
    """
    Which driver reaches the hardware. `feetech`: a bus of Feetech STS serial servos, one per joint, through feetech-servo-sdk (LeRobot's SO-100 and SO-101 arms); its wiring is `feetech`. `ros2_control`: the robot's own ROS 2 driver (franka_ros2, ur_robot_driver, xarm_ros2, ...) with a joint_state_broadcaster and a joint_trajectory_controller, reached over ROS 2 in the namespace given on the command line (`--transport ros2_control:<namespace>`); its names are `ros2_control`.
    """
    control_rate_hz: Annotated[StrictFloat, Field(ge=1.0, le=1000.0)] = 100.0
    """
    How often the driver reads the joints and writes their goals [Hz], 1 to 1000. Every /joint_states message of `deploy real` is one such read; the E-stop latches within two periods of a bus that stops answering. 100 Hz by default: a Feetech bus at 1 Mbaud reads and writes six servos in about 2 ms.
    """
    estop: Estop = Estop.hold
    """
    What the E-stop does to the motors, within one control period: `hold` keeps torque on and holds the last measured position (the arm stays where it is); `torque_off` cuts torque (the arm goes limp and falls under gravity unless it rests).
    """
    shutdown: Shutdown = Shutdown.torque_off
    """
    The motors' torque state after the driver stops (Ctrl-C, SIGTERM, disconnect): first every joint holds its last measured position, then `hold` leaves torque on (the servos keep holding with nothing watching them) or `torque_off` releases it (LeRobot's choice: rest the arm first, it falls).
    """
    first_motion_speed_scale: Annotated[StrictFloat, Field(gt=0.0, le=1.0)] = 0.2
    """
    Share of each joint's velocity_limit the first motion may use, after connect and after an E-stop release, until the goals the driver writes have caught up with the command once; afterwards the whole velocity_limit applies. Keeps a first command far from the measured pose from being a jump.
    """
    refuse_zero_action: StrictBool = True
    """
    Refuse an action whose every value is exactly 0. On an absolute-position arm it commands every joint to 0 rad (and the gripper shut), which is what an uninitialised or 'zero means hold' client sends by mistake; hold is the measured position, sent as the action spec's hold action.
    """
    feetech: FeetechBus | None = None
    """
    The Feetech bus (with `driver: feetech`); see FeetechBus.
    """
    ros2_control: Ros2ControlDriver | None = None
    """
    The robot driver's controllers (with `driver: ros2_control`); see Ros2ControlDriver. Absent: every default.
    """
