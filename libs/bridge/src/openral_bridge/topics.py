"""The ROS names of the openral graph, in one place for the node, the bridge and the runner.

Pure constants and the :class:`TopicInfo` record (no rclpy, no MuJoCo), so any process can
import them cheaply.
"""

from __future__ import annotations

from dataclasses import dataclass

JOINT_STATES = "/joint_states"
"""sensor_msgs/JointState: every joint of the robot's URDF in SI units (manifest joints under
their canonical names)."""
MANIFEST_JOINT_STATES = "/openral/manifest_joint_states"
"""sensor_msgs/JointState: the manifest's joints in manifest units (a gripper in its read
mode), as a policy sees them in an episode."""
TF = "/tf"
"""tf2_msgs/TFMessage: the transforms that move (links on joints, a moving base)."""
TF_STATIC = "/tf_static"
"""tf2_msgs/TFMessage, latched: the transforms fixed between resets."""
ROBOT_DESCRIPTION = "/robot_description"
"""std_msgs/String, latched: the robot's URDF."""
ROBOT_DESCRIPTION_SEMANTIC = "/robot_description_semantic"
"""std_msgs/String, latched: the robot's SRDF (MoveIt's groups, states, collision pairs)."""
JTC_NAME = "joint_trajectory_controller"
"""The joint trajectory controller's name (ros2_control's usual one, MoveIt's default)."""
FOLLOW_JOINT_TRAJECTORY = f"/{JTC_NAME}/follow_joint_trajectory"
"""control_msgs/action/FollowJointTrajectory: the joint trajectory action (MoveIt's)."""
JTC_JOINT_TRAJECTORY = f"/{JTC_NAME}/joint_trajectory"
"""trajectory_msgs/JointTrajectory: the controller's topic (as :data:`JOINT_TRAJECTORY`)."""
JTC_STATE = f"/{JTC_NAME}/controller_state"
"""control_msgs/JointTrajectoryControllerState: reference, feedback, error and output."""
GRIPPER_NAME = "gripper_controller"
"""The parallel gripper's controller name."""
GRIPPER_COMMAND = f"/{GRIPPER_NAME}/gripper_cmd"
"""control_msgs/action/GripperCommand: open and close the gripper (MoveIt's gripper action)."""
JSB_NAME = "joint_state_broadcaster"
"""The joint state broadcaster's name (it publishes :data:`JOINT_STATES`)."""
DYNAMIC_JOINT_STATES = "/dynamic_joint_states"
"""control_msgs/DynamicJointState: every joint's position, velocity and effort interfaces."""
CONTROLLER_MANAGER = "/controller_manager"
"""Prefix of the controller manager's services (list_controllers, list_hardware_interfaces,
switch_controller: controller_manager_msgs)."""
CLOCK = "/clock"
"""rosgraph_msgs/Clock: simulation time."""
ACTION_SPEC = "/openral/action_spec"
"""sensor_msgs/JointState, latched: action slot names and the hold action."""
SAFE_ACTION = "/openral/safe_action"
"""std_msgs/Float64MultiArray: one value per action slot."""
ESTOP = "/openral/estop"
"""std_srvs/Trigger: latch the E-stop."""
RELEASE_ESTOP = "/openral/release_estop"
"""std_srvs/Trigger: release the E-stop."""
JOINT_TRAJECTORY = "/openral/joint_trajectory"
"""trajectory_msgs/JointTrajectory: joints by manifest name, followed by the control loop."""
JOINT_TRAJECTORY_REFUSED = "/openral/joint_trajectory/refused"
"""std_msgs/String: why a trajectory on the topic was refused (one message per refusal)."""
JOINT_TRAJECTORY_STATE = "/openral/joint_trajectory/state"
"""sensor_msgs/JointState: the desired point of the running trajectory, once per tick."""
RESET = "/openral/reset"
"""std_srvs/Trigger: reset the scene to its seed and start pose."""
EE_TARGET = "/openral/ee_target"
"""geometry_msgs/PoseStamped: where the tool centre point should go, in the base frame."""
EE_TARGET_STATE = "/openral/ee_target/state"
"""sensor_msgs/JointState: the arm's targets of the IK's step, once per tick towards a target."""
EE_TARGET_REFUSED = "/openral/ee_target/refused"
"""std_msgs/String: why a target on :data:`EE_TARGET` was refused (one message per refusal)."""
TCP_POSE = "/openral/tcp_pose"
"""geometry_msgs/PoseStamped: the tool centre point's pose in the base frame."""
CMD_VEL = "/cmd_vel"
"""geometry_msgs/Twist: the mobile base's velocity command, base frame."""
ODOM = "/odom"
"""nav_msgs/Odometry: the mobile base's pose (odometry frame) and twist (base frame)."""
SCAN = "/scan"
"""sensor_msgs/LaserScan of a robot's only lidar (with more: ``/scan/<sensor>``)."""


def camera_image(sensor: str) -> str:
    """sensor_msgs/Image (rgb8) of one manifest RGB sensor."""
    return f"/openral/cameras/{sensor}/image"


def camera_info(sensor: str) -> str:
    """sensor_msgs/CameraInfo of one manifest RGB or depth sensor."""
    return f"/openral/cameras/{sensor}/camera_info"


def scan(sensor: str, only: bool) -> str:
    """sensor_msgs/LaserScan of one lidar: :data:`SCAN` when it is the robot's only one."""
    return SCAN if only else f"{SCAN}/{sensor}"


def depth_image(sensor: str) -> str:
    """sensor_msgs/Image (32FC1, metres) of one manifest depth sensor."""
    return f"/openral/cameras/{sensor}/depth"


def depth_points(sensor: str) -> str:
    """sensor_msgs/PointCloud2 of one depth sensor, in the robot's base frame."""
    return f"/openral/cameras/{sensor}/points"


def imu(sensor: str) -> str:
    """sensor_msgs/Imu of one manifest IMU."""
    return f"/openral/imu/{sensor}"


def wrench(sensor: str) -> str:
    """geometry_msgs/WrenchStamped of one manifest force-torque sensor, in its site frame."""
    return f"/openral/wrench/{sensor}"


def pose(sensor: str) -> str:
    """geometry_msgs/PoseStamped of one manifest pose sensor, in the world frame."""
    return f"/openral/pose/{sensor}"


@dataclass(frozen=True)
class TopicInfo:
    """One topic a node publishes: name, message type and nominal rate (None: on change)."""

    name: str
    type: str
    rate_hz: float | None
    when: str = ""
    """When it publishes, if not always (``while moving``: while a joint trajectory runs)."""
