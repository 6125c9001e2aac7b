"""The mobile Panda's room, checked from outside the graph: ``openral deploy sim`` as a
subprocess, read and driven by a client on a domain of its own, as a nav stack would.

- ``/scan`` has finite ranges (walls all round), the head depth camera's cloud is not empty,
  ``/odom`` is published;
- ``/cmd_vel`` at 0.3 m/s, sent at 20 Hz for 2.0 s and then a zero Twist, moves the base
  0.6 ± 0.05 m along x in ``/odom`` and on ``/joint_states`` (its x slide); the control
  loop runs in real time, so 2.0 s of wall time is 2.0 s of simulated time;
- after the E-stop is latched the base is at a standstill within 0.2 s (of wall time, in
  ``/odom``), and ``/cmd_vel`` no longer moves it.
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from openral_bridge.topics import (
    CMD_VEL,
    ESTOP,
    JOINT_STATES,
    ODOM,
    ROBOT_DESCRIPTION,
    SCAN,
    depth_points,
)
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from openral_nodes.topic_codec import cloud_points
from sensor_msgs.msg import JointState, LaserScan, PointCloud2
from std_msgs.msg import String
from std_srvs.srv import Trigger

from tests.conftest import ROBOTS
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import Probe

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone

ROOM = ROBOTS / "panda_mobile" / "scenes" / "room.yaml"
POINTS = depth_points("head_depth")
START_WAIT_S = 90.0
"""Longest wait for deploy sim to load its scene and publish on a loaded machine [s]."""


class Client:
    """A probe of the room's streams and a /cmd_vel publisher on one spun context."""

    def __init__(self, probe: Probe, spinner: Spinner) -> None:
        self.probe, self.spinner = probe, spinner
        self.twist = probe.node.create_publisher(Twist, CMD_VEL, 10)
        self.estop = probe.node.create_client(Trigger, ESTOP)

    def drive(self, vx: float, seconds: float) -> None:
        """Send ``vx`` at 20 Hz from now until ``seconds`` of wall time later (both ends)."""
        msg = Twist()
        msg.linear.x = vx
        start = time.monotonic()
        for index in range(round(seconds * 20) + 1):
            time.sleep(max(0.0, start + index / 20 - time.monotonic()))
            self.twist.publish(msg)


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Client]:
    logs = tmp_path_factory.mktemp("mobile_live")
    domain = claim_domain_id()
    topics = {
        SCAN: LaserScan,
        POINTS: PointCloud2,
        ODOM: Odometry,
        JOINT_STATES: JointState,
        ROBOT_DESCRIPTION: String,  # out once the start-up work beside the loop is done
    }
    with ros_session(domain_id=domain) as context, deploy_sim(ROOM, domain, logs) as process:
        probe = Probe(context, topics, name="mobile_client")
        with Spinner(context) as spinner:
            spinner.add_node(probe.node)
            for topic in topics:
                probe.wait_count(topic, 1, timeout_s=START_WAIT_S)
            client = Client(probe, spinner)
            deadline = time.monotonic() + 10.0
            while client.twist.get_subscription_count() == 0 and time.monotonic() < deadline:
                time.sleep(0.05)
            assert process.poll() is None, deploy_output(logs)
            yield client
        probe.node.destroy_node()  # type: ignore[no-untyped-call]


def test_scan_cloud_and_odom_are_published(client: Client) -> None:
    scan = client.probe.latest(SCAN)
    ranges = np.asarray(scan.ranges)
    assert len(ranges) == 270 and np.isfinite(ranges).all()  # walls within 10 m all round
    assert scan.range_min <= ranges.min() and ranges.max() <= scan.range_max
    points = cloud_points(client.probe.latest(POINTS))
    assert len(points) > 100 and np.isfinite(points).all()
    assert client.probe.latest(POINTS).header.frame_id == "base_link"
    odom = client.probe.latest(ODOM)
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")


def _forward_slide(client: Client) -> float:
    """The base's x slide [m] on the latest /joint_states (after the manifest's joints)."""
    msg = client.probe.latest(JOINT_STATES)
    assert list(msg.name[:8]) == [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
    return float(msg.position[list(msg.name).index("joint_mobile_forward")])


def test_cmd_vel_for_2_s_moves_the_base_0_6_m(client: Client) -> None:
    x0 = client.probe.latest(ODOM).pose.pose.position.x
    slide0 = _forward_slide(client)
    client.drive(0.3, 2.0)
    client.drive(0.0, 0.0)
    time.sleep(1.0)  # the ramp down, and /odom of the standstill
    odom = client.probe.latest(ODOM)
    print(f"/cmd_vel 0.3 m/s for 2.0 s: {odom.pose.pose.position.x - x0:.4f} m in /odom")
    assert odom.pose.pose.position.x - x0 == pytest.approx(0.6, abs=0.05)
    print(f"joint_mobile_forward on /joint_states: {_forward_slide(client) - slide0:.4f} m")
    assert _forward_slide(client) - slide0 == pytest.approx(0.6, abs=0.05)  # the scene's
    assert abs(odom.pose.pose.position.y) < 0.02
    assert abs(odom.twist.twist.linear.x) < 0.01


def test_the_base_stops_within_0_2_s_of_the_estop(client: Client) -> None:
    client.drive(0.3, 1.0)
    assert client.probe.latest(ODOM).twist.twist.linear.x > 0.2
    assert client.estop.wait_for_service(timeout_sec=5.0)
    before = time.monotonic()
    future = client.estop.call_async(Trigger.Request())
    while not future.done():  # type: ignore[no-untyped-call]
        time.sleep(0.005)
    answer = future.result()  # type: ignore[no-untyped-call]
    assert answer is not None and answer.success
    time.sleep(0.3)
    standing = [
        r for r in client.probe.since(ODOM, before) if abs(r.msg.twist.twist.linear.x) < 1e-6
    ]
    assert standing, "the base never stood still after the E-stop"
    print(f"standstill in /odom {standing[0].at - before:.3f} s after the E-stop request")
    assert standing[0].at - before < 0.2
    x = client.probe.latest(ODOM).pose.pose.position.x
    client.drive(0.3, 0.5)  # refused while latched
    time.sleep(0.2)
    assert client.probe.latest(ODOM).pose.pose.position.x == pytest.approx(x, abs=1e-9)
