"""IMU and force-torque topics of live graphs, read from outside as a ROS client would.

- franka tabletop: ``/openral/wrench/wrist_ft`` (``geometry_msgs/WrenchStamped``) is
  stamped with a ``/clock`` time, framed ``ft_sensor_link``, and its force's magnitude is
  the weight beyond the sensor (subtree mass of ``hand`` in the robot's own model, times
  9.81) within 2 %; ``openral ros topics`` lists it, ``openral ros echo`` prints it;
- g1 tabletop (pelvis welded): ``/openral/imu/pelvis_imu`` (``sensor_msgs/Imu``) reads
  9.81 ± 0.05 m/s² along z (the pelvis stands upright) and |angular velocity| < 0.01 rad/s.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import mujoco
import numpy as np
import pytest
from geometry_msgs.msg import WrenchStamped
from openral_bridge.topics import CLOCK, imu, wrench
from openral_core import open_robot_by_id
from openral_mujoco.mjcf_uri import resolve_mjcf_uri
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu

from tests.conftest import ROBOTS
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import Probe

START_WAIT_S = 90.0
OPENRAL = Path(sys.executable).parent / "openral"
WRENCH, IMU = wrench("wrist_ft"), imu("pelvis_imu")


def _graph(robot_id: str, topics: dict[str, object], logs: Path) -> Iterator[tuple[Probe, int]]:
    domain = claim_domain_id()
    scene = ROBOTS / robot_id / "scenes" / "tabletop.yaml"
    with ros_session(domain_id=domain) as context, deploy_sim(scene, domain, logs) as process:
        probe = Probe(context, topics, name=f"{robot_id}_sensor_client")
        with Spinner(context) as spinner:
            spinner.add_node(probe.node)
            for topic in topics:
                probe.wait_count(topic, 20, timeout_s=START_WAIT_S)
            assert process.poll() is None, deploy_output(logs)
            yield probe, domain
        probe.node.destroy_node()  # type: ignore[no-untyped-call]


@pytest.fixture(scope="module")
def franka(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Probe, int]]:
    topics = {WRENCH: WrenchStamped, CLOCK: Clock}
    yield from _graph("franka_panda", topics, tmp_path_factory.mktemp("franka_sensors"))


def _hand_weight() -> float:
    robot = open_robot_by_id("franka_panda").description
    assert robot.sim is not None
    model = mujoco.MjModel.from_xml_path(str(resolve_mjcf_uri(robot.sim.mjcf_uri)))
    hand = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hand")
    return float(model.body_subtreemass[hand]) * 9.81


def _stamp(msg: object) -> int:
    stamp = msg.header.stamp  # type: ignore[attr-defined]
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def test_the_panda_wrist_wrench_is_the_hand_weight_in_sim_time(franka: tuple[Probe, int]) -> None:
    probe, _ = franka
    msg = probe.latest(WRENCH)
    force = msg.wrench.force
    magnitude = float(np.linalg.norm([force.x, force.y, force.z]))
    print(f"|F| {magnitude:.4f} N, weight beyond the sensor {_hand_weight():.4f} N")
    assert magnitude == pytest.approx(_hand_weight(), rel=0.02)
    assert msg.header.frame_id == "ft_sensor_link"
    clocks = {
        int(m.msg.clock.sec) * 1_000_000_000 + int(m.msg.clock.nanosec)
        for m in probe.since(CLOCK, 0.0)
    }
    stamps = [_stamp(m.msg) for m in probe.since(WRENCH, 0.0)]
    assert set(stamps[-10:]) <= clocks  # each is the simulated time of a control step


def test_the_cli_lists_and_prints_the_wrench(franka: tuple[Probe, int]) -> None:
    _, domain = franka
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    topics = subprocess.run(
        [str(OPENRAL), "ros", "topics"], capture_output=True, text=True, env=env, timeout=60
    )
    rows = [line for line in topics.stdout.splitlines() if WRENCH in line]
    assert len(rows) == 1 and "geometry_msgs/msg/WrenchStamped" in rows[0]
    echo = subprocess.run(
        [str(OPENRAL), "ros", "echo", WRENCH, "--once"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert echo.returncode == 0, echo.stderr
    assert (
        "frame_id: ft_sensor_link" in echo.stdout
        and "force:" in echo.stdout
        and "torque:" in echo.stdout
    )


def test_the_g1_pelvis_imu_reads_gravity_and_no_rotation(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    topics = {IMU: Imu}
    for probe, _ in _graph("g1", topics, tmp_path_factory.mktemp("g1_sensors")):
        msg = probe.latest(IMU)
        acc, gyro = msg.linear_acceleration, msg.angular_velocity
        print(f"g1 pelvis IMU: acceleration ({acc.x:.4f}, {acc.y:.4f}, {acc.z:.4f}) m/s²")
        assert acc.z == pytest.approx(9.81, abs=0.05)
        assert float(np.linalg.norm([gyro.x, gyro.y, gyro.z])) < 0.01
        assert msg.header.frame_id == "imu_in_pelvis"
        assert msg.orientation.w == pytest.approx(1.0, abs=1e-3)
