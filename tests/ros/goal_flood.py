"""A flood of trajectory goals and 1e5-name trajectories from a process of its own.

``python -m tests.ros.goal_flood DOMAIN Q1 Q2`` (from the repository root; Q1, Q2: the
current positions of the two joints of ``JOINTS`` [rad]) sends :data:`FLOOD_HZ` goals a
second to the graph's FollowJointTrajectory server, good and NaN in turn, and a
trajectory naming one joint 1e5 times on the trajectory topic twice a second, until its
standard input closes; then it prints how many goals it sent. Its own process, so that
serialising those messages never competes with the measuring test for its GIL.
"""

from __future__ import annotations

import sys
import threading
import time

from openral_bridge.topics import JOINT_TRAJECTORY
from openral_nodes.runtime import Spinner, ros_session
from openral_nodes.trajectory_request import trajectory_msg
from rclpy.node import Node
from trajectory_msgs.msg import JointTrajectory

from tests.ros.action_client import TrajectoryActionClient, goal
from tests.ros.trajectory_client import JOINTS

FLOOD_HZ = 100.0
"""Goals per second."""
READY = "flooding"
"""Printed once the first goal is out."""


def _flood(node: Node, q: list[float], stop: threading.Event) -> int:
    action = TrajectoryActionClient(node)
    trajectories = node.create_publisher(JointTrajectory, JOINT_TRAJECTORY, 10)
    good = goal(JOINTS, [(0.5, [v + 0.01 for v in q])])
    bad = goal(JOINTS, [(1.0, [q[0], float("nan")])])
    names = trajectory_msg(("panda_joint1",) * 100_000, [1.0], [[q[0]] * 100_000])
    count, next_at = 0, time.monotonic()
    while not stop.is_set():
        action.client.send_goal_async(good if count % 2 else bad)
        if count % 50 == 0:
            trajectories.publish(names)
        if count == 0:
            print(READY, flush=True)
        count += 1
        next_at += 1.0 / FLOOD_HZ
        time.sleep(max(0.0, next_at - time.monotonic()))
    return count


def main(argv: list[str]) -> None:
    """Flood domain ``argv[0]`` until standard input closes (see the module doc)."""
    domain, q = int(argv[0]), [float(v) for v in argv[1:]]
    stop = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.read(), stop.set()), daemon=True).start()
    with ros_session(domain_id=domain) as context, Spinner(context) as spinner:
        node = Node("goal_flood", context=context)
        spinner.add_node(node)
        count = _flood(node, q, stop)
        spinner.stop()
        node.destroy_node()  # type: ignore[no-untyped-call]
    print(count, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
