"""Send one joint trajectory to a running ``openral deploy sim`` graph with plain rclpy.

Run it next to the Panda's default scene (``ROS_DOMAIN_ID`` as the graph's)::

    python docs/examples/send_trajectory.py

It reads the joints' positions on ``/joint_states``, moves panda_joint1 by +0.3 rad in
1.5 s with a cubic (zero velocities at both ends), and prints the last desired point
the graph published on ``/openral/joint_trajectory/state``.
"""

from __future__ import annotations

import time

import rclpy
from builtin_interfaces.msg import Duration
from rclpy.node import Node
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint


def main() -> None:
    rclpy.init()
    node = Node("send_trajectory_example")
    latest: dict[str, JointState] = {}
    node.create_subscription(JointState, "/joint_states", lambda m: latest.update(now=m), 10)
    node.create_subscription(
        JointState, "/openral/joint_trajectory/state", lambda m: latest.update(desired=m), 10
    )
    publisher = node.create_publisher(JointTrajectory, "/openral/joint_trajectory", 10)
    deadline = time.monotonic() + 20.0
    while ("now" not in latest or publisher.get_subscription_count() == 0) and (
        time.monotonic() < deadline
    ):
        rclpy.spin_once(node, timeout_sec=0.1)
    start = latest["now"].position[list(latest["now"].name).index("panda_joint1")]

    msg = JointTrajectory(joint_names=["panda_joint1"])  # header stamp 0: start now
    msg.points = [
        JointTrajectoryPoint(positions=[start], velocities=[0.0], time_from_start=Duration()),
        JointTrajectoryPoint(
            positions=[start + 0.3],
            velocities=[0.0],
            time_from_start=Duration(sec=1, nanosec=500_000_000),
        ),
    ]
    publisher.publish(msg)
    end = time.monotonic() + 3.0
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    desired = latest["desired"]
    print(f"last desired point: {desired.name[0]} = {desired.position[0]:.4f} rad")
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
