"""Ros2ControlHal against deploy sim as the robot: deploy sim runs the Panda in namespace
``robot`` (its ros2_control surface: /robot/joint_states, the trajectory controller's topic,
the gripper action) and the HAL drives it as it would drive franka_ros2 on the arm. Killing
the robot latches the HAL's E-stop two control periods after its last reading, with one
line; nothing is sent after it; a robot started again and a release resume."""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from openral_core import open_robot_by_id
from openral_hal.errors import ConfigurationError, EStopLatched
from openral_hal.factory import RealOptions, build_hal
from openral_hal.realtime import ahead_of_other_programs
from openral_nodes.runtime import claim_domain_id
from openral_real.ros2_control_hal import Ros2ControlHal
from openral_real.ros2_control_link import driver_namespace

from tests.conftest import ROBOTS
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import wait_until

pytestmark = pytest.mark.exclusive  # a stream late by two 10 ms periods latches: run alone

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
PERIOD_S = 0.01
"""The Panda's real.control_rate_hz is 100."""
WAKE_SLACK_S = 0.003
"""How late the watchdog's thread may wake on a loaded machine [s]."""
RELEASES = 3
"""Releases the restart may take: the stand-in robot (a Python simulator on two shared
cores) misses its 20 ms deadline now and then after it starts, and the HAL latches, as it
must; each latch must name the stream."""


@pytest.fixture(scope="module")
def robot_driver(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[object, Path]]:
    """deploy sim as the robot, in namespace /robot, on a domain of its own."""
    logs = tmp_path_factory.mktemp("robot")
    domain = claim_domain_id()
    before = os.environ.get("ROS_DOMAIN_ID")
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    try:
        with deploy_sim(SCENE, domain, logs, ("--namespace", "robot"), robot=True) as process:
            yield process, logs
    finally:
        if before is None:
            os.environ.pop("ROS_DOMAIN_ID", None)
        else:
            os.environ["ROS_DOMAIN_ID"] = before


@pytest.fixture
def hal(robot_driver: tuple[object, Path]) -> Iterator[Ros2ControlHal]:
    robot = open_robot_by_id("franka_panda")
    options = RealOptions()
    built = build_hal(robot, mode="real", transport="ros2_control:robot", real_options=options)
    assert isinstance(built, Ros2ControlHal)
    with ahead_of_other_programs():  # as deploy real runs it
        built.connect()
        try:
            yield built
        finally:
            built.disconnect()


def test_a_transport_that_is_no_namespace_is_one_line() -> None:
    assert driver_namespace("ros2_control:/panda/") == "/panda"
    assert driver_namespace("ros2_control:") == ""
    for bad in (None, "/dev/ttyACM0", "ros2_control:9lives", "ros2_control:a b"):
        with pytest.raises(ConfigurationError) as raised:
            driver_namespace(bad)
        assert "ros2_control:" in str(raised.value) and "\n" not in str(raised.value)


def test_it_reads_the_robot_and_holds_it_where_it_is(hal: Ros2ControlHal) -> None:
    state = hal.read_state()
    assert not state.stale and state.names[0] == "panda_joint1"
    start = np.array([0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398])
    np.testing.assert_allclose(state.positions[:7], start, atol=0.02)
    np.testing.assert_allclose(hal.hold_action(), state.positions, atol=0.01)
    with pytest.raises(Exception, match="all-zero action"):
        hal.send_action(np.zeros(8))


def test_an_action_moves_the_robots_arm_and_gripper(hal: Ros2ControlHal) -> None:
    sent, readings = hal.sent, hal.readings
    target = hal.hold_action()
    target[0] += 0.3
    gripper_open = target[7]
    target[7] = 0.2 * gripper_open  # most of the way shut
    hal.send_action(target)
    arm = lambda: abs(hal.read_state().positions[0] - target[0]) < 0.01  # noqa: E731
    wait_until(lambda: hal.estopped or arm(), 10.0, "joint 1")
    assert not hal.estopped, hal.estop_reason
    wait_until(lambda: hal.read_state().positions[7] < 0.5 * gripper_open, 10.0, "the gripper")
    moved_sent, moved_readings = hal.sent - sent, hal.readings - readings
    print(f"{moved_sent} goals sent over {moved_readings} readings")
    assert moved_readings > 10 and moved_sent >= moved_readings - 2  # one goal per reading


def test_killing_the_robot_latches_the_estop_within_two_periods_and_a_restart_resumes(
    robot_driver: tuple[object, Path], hal: Ros2ControlHal, tmp_path: Path
) -> None:
    process, logs = robot_driver
    faults: list[tuple[float, str]] = []
    hal.on_fault = lambda line: faults.append((time.monotonic(), line))
    assert process.poll() is None, deploy_output(logs)  # type: ignore[attr-defined]
    process.kill()  # type: ignore[attr-defined]
    process.wait(10)  # type: ignore[attr-defined]
    wait_until(lambda: bool(faults), 5.0, "the E-stop")
    sent = hal.sent
    assert hal.estopped and len(faults) == 1
    assert "joint_states stopped" in faults[0][1] and "\n" not in faults[0][1]
    latency_s = faults[0][0] - hal.received_s  # both stamps of this process's monotonic clock
    print(f"E-stop latched {latency_s * 1000:.1f} ms after the last reading")
    assert latency_s <= 2 * PERIOD_S + WAKE_SLACK_S, f"{latency_s * 1000:.1f} ms"
    time.sleep(0.2)
    assert hal.sent == sent  # nothing sent after the latch
    with pytest.raises(EStopLatched):
        hal.release_estop()
    domain = int(os.environ["ROS_DOMAIN_ID"])
    with deploy_sim(SCENE, domain, tmp_path, ("--namespace", "robot"), robot=True):
        wait_until(lambda: not hal.read_state().stale, 90.0, "the restarted robot's readings")
        _steady(hal)  # its discovery may pause the stream once: release after it
        assert hal.estopped and hal.sent == sent  # a robot back is no release
        for _ in range(RELEASES):  # the stand-in robot misses its deadline now and then
            hal.release_estop()
            if _turned(hal, -0.2):
                break
            assert "joint_states stopped" in faults[-1][1], faults[-1][1]  # the stream rule
            _steady(hal)
        assert not hal.estopped, hal.estop_reason


def _turned(hal: Ros2ControlHal, by_rad: float) -> bool:
    """Send joint 1 ``by_rad`` from where it holds; True once it is there, False when the
    E-stop latches first (10 s at most)."""
    target = hal.hold_action()
    target[0] += by_rad
    hal.send_action(target)
    there = lambda: abs(hal.read_state().positions[0] - target[0]) < 0.01  # noqa: E731
    wait_until(lambda: hal.estopped or there(), 10.0, "joint 1 after the release")
    return not hal.estopped


def _steady(hal: Ros2ControlHal, seconds: float = 2.0) -> None:
    """Wait until the readings have stayed fresh for ``seconds`` on end."""
    deadline = time.monotonic() + 60.0
    since = time.monotonic()
    while time.monotonic() - since < seconds:
        assert time.monotonic() < deadline, "no steady stream from the restarted robot"
        if hal.read_state().stale:
            since = time.monotonic()
        time.sleep(0.002)
