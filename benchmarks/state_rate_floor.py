"""The floor under ``deploy sim``'s CPU line: what publishing the robot's state at 100 Hz
costs a bare rclpy process, against the rates before the state rate (20 Hz ticks, 50 Hz
joint states).

A child process does nothing but publish what the graph publishes per tick on the franka
tabletop, with a subscriber to ``/joint_states`` in this process as ``bench-deploy`` has:
``/clock``, ``/joint_states`` and ``/openral/manifest_joint_states`` (9 and 8 joints),
``/dynamic_joint_states``, ``/tf`` (11 transforms) and the TCP pose, filled anew each time.
Its CPU (``/proc``, 100 % = one core) at the old rates and at 100 Hz is the least any
implementation in rclpy pays for the new rates on this machine, whatever the simulation
costs. Run with ``python -m benchmarks.state_rate_floor``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from benchmarks.deploy_launch import deploy_env

WINDOW_S = 10.0
CHILD = r"""
import sys, time
import rclpy
from builtin_interfaces.msg import Time
from control_msgs.msg import DynamicJointState, InterfaceValue
from geometry_msgs.msg import PoseStamped, TransformStamped
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
tick_hz, state_hz, seconds = (float(v) for v in sys.argv[1:4])
rclpy.init()
node = rclpy.create_node("state_floor")
kinds = [("/clock", Clock), ("/joint_states", JointState), ("/tf", TFMessage),
         ("/openral/manifest_joint_states", JointState), ("/openral/tcp_pose", PoseStamped),
         ("/dynamic_joint_states", DynamicJointState)]
pubs = {n: node.create_publisher(t, n, 10) for n, t in kinds}
names = [f"j{i}" for i in range(9)]
start = time.monotonic(); k = 0
base_hz = 100.0
while time.monotonic() - start < seconds:
    t = k / base_hz
    stamp = Time(sec=int(t), nanosec=int((t % 1) * 1e9))
    ticked = k % round(base_hz / tick_hz) == 0
    if ticked:
        pubs["/clock"].publish(Clock(clock=stamp))
    if k % round(base_hz / state_hz) == 0:
        for topic, n in (("/joint_states", 9), ("/openral/manifest_joint_states", 8)):
            zeros = [0.0] * n
            msg = JointState(name=names[:n], position=[0.1] * n, velocity=zeros, effort=zeros)
            msg.header.stamp = stamp
            pubs[topic].publish(msg)
        values = [InterfaceValue(interface_names=["position", "velocity", "effort"],
                                 values=[0.1, 0.0, 0.0]) for _ in names]
        pubs["/dynamic_joint_states"].publish(
            DynamicJointState(joint_names=names, interface_values=values))
        pose = PoseStamped(); pose.header.stamp = stamp
        pubs["/openral/tcp_pose"].publish(pose)
    transforms = []
    for i in range(11 if ticked else 0):
        tr = TransformStamped(); tr.header.stamp = stamp; tr.header.frame_id = f"l{i}"
        tr.child_frame_id = f"l{i + 1}"; tr.transform.translation.x = 0.1
        tr.transform.rotation.w = 1.0
        transforms.append(tr)
    if ticked:
        pubs["/tf"].publish(TFMessage(transforms=transforms))
    k += 1
    time.sleep(max(0.0, start + k / base_hz - time.monotonic()))
"""


def cpu_percent(tick_hz: float, state_hz: float) -> float:
    """The child's CPU [% of one core] over :data:`WINDOW_S` at these rates."""
    import rclpy
    from sensor_msgs.msg import JointState

    env = deploy_env(ROS_DOMAIN_ID=str(100 + os.getpid() % 100))
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(tick_hz), str(state_hz), str(WINDOW_S + 4)], env=env
    )
    os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
    rclpy.init()
    node = rclpy.create_node("state_floor_listener")
    got: list[float] = []
    node.create_subscription(JointState, "/joint_states", lambda m: got.append(1.0), 10)
    try:
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.05)
        stat = Path(f"/proc/{child.pid}/stat")
        before = sum(int(v) for v in stat.read_text().split()[13:15])
        wall0 = time.monotonic()
        while time.monotonic() - wall0 < WINDOW_S:
            rclpy.spin_once(node, timeout_sec=0.05)
        after = sum(int(v) for v in stat.read_text().split()[13:15])
        ticks = os.sysconf("SC_CLK_TCK")
        return 100.0 * (after - before) / ticks / (time.monotonic() - wall0)
    finally:
        node.destroy_node()
        rclpy.shutdown()
        child.wait()


def main() -> None:
    old = cpu_percent(20.0, 50.0)
    new = cpu_percent(100.0, 100.0)
    print(f"bare rclpy publishing, old rates (20 Hz tick, 50 Hz state): {old:.1f} % of a core")
    print(f"bare rclpy publishing, 100 Hz state:                        {new:.1f} % of a core")
    print(f"floor of the added CPU: {new - old:+.1f} points")


if __name__ == "__main__":
    main()
