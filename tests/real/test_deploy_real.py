"""``openral deploy real`` as a subprocess, driving an emulated SO-101 bus (on the emulator,
not on hardware): the graph of deploy sim on a real driver, policies and goals moving the
servos, E-stop, faults, a clean stop, and bad input said in one line. The emulator answers
in real time beside the driver: these run in the exclusive phase."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from openral_nodes.service_call import call_trigger
from rclpy.node import Node

from tests.real.deploy_helpers import (
    Remote,
    RemoteBus,
    camera_clip,
    deploy_real,
    joints_now,
    openral,
    remote_graph,
    stop,
)
from tests.ros.action_client import TrajectoryActionClient, goal

pytestmark = pytest.mark.exclusive  # a servo bus emulated in real time, beside its driver
SUCCEEDED = 4
ARM = ("shoulder_pan", "elbow_flex", "wrist_flex")


@pytest.fixture
def bus(tmp_path: Path) -> Iterator[RemoteBus]:
    """An emulated SO-101 bus in a process of its own, calibrated."""
    remote = RemoteBus(tmp_path)
    yield remote
    remote.close()


def _torque(bus: RemoteBus) -> list[int]:
    return [int(x) for x in re.findall(r"torque (\d)", bus.command("status"))]


def _serving(remote: Remote) -> None:
    remote.probe.wait_count("/joint_states", 1, timeout_s=40.0)


def test_one_graph_wave_a_three_point_goal_estop_and_a_clean_stop(
    bus: RemoteBus, tmp_path: Path
) -> None:
    """One deploy real, as a user runs it: cameras from clips, `rskill run --policy wave`,
    a 3-point FollowJointTrajectory goal, E-stop and release, reset refused, Ctrl-C."""
    clip = camera_clip(tmp_path / "clip.mp4")
    cameras = ("--camera", f"front=file:{clip}", "--camera", f"wrist=file:{clip}")
    with remote_graph() as remote:
        process = deploy_real(bus.path, bus.calibration, remote.domain, *cameras)
        client = Node("real_client", context=remote.context)
        remote.spinner.add_node(client)
        try:
            _serving(remote)
            _joint_states_are_fresh_at_the_read_rate(remote)
            _cameras_publish(remote)
            _wave_moves_the_servos(bus, remote)
            try:
                _three_point_goal(remote, client)
            except AssertionError:
                print("deploy real said:", stop(process)[1][-3000:])
                raise
            _estop_release_and_reset(client)
            stopped = time.time()
            out, err = stop(process)
        finally:
            remote.spinner.remove_node(client)
            client.destroy_node()  # type: ignore[no-untyped-call]
            stop(process)
    assert process.returncode == 0, err
    assert "stopped (signal)" in out and "clean shutdown" in out and "Traceback" not in err
    assert "nothing moves until it is released" not in err  # no fault latched on the way
    writes = [line.split()[1:3] for line in bus.lines(stopped)]
    writes = [kind for kind in writes if kind[0] == "SYNC_WRITE"]
    assert writes[-2:] == [["SYNC_WRITE", "Goal_Position"], ["SYNC_WRITE", "Torque_Enable"]]
    assert _torque(bus) == [0] * 6


def _joint_states_are_fresh_at_the_read_rate(remote: Remote) -> None:
    """/joint_states: one message per bus reading, 100 a second (±5 %), ≥ 95 % new stamps."""
    time.sleep(0.5)
    began = time.monotonic()
    time.sleep(3.0)
    received = [r for r in remote.probe.since("/joint_states", began) if r.at < began + 3.0]
    stamps = {(r.msg.header.stamp.sec, r.msg.header.stamp.nanosec) for r in received}
    assert len(received) / 3.0 == pytest.approx(100.0, rel=0.05)
    assert len(stamps) / len(received) >= 0.95


def _cameras_publish(remote: Remote) -> None:
    remote.probe.wait_count("/openral/cameras/front/image", 2, timeout_s=10.0)
    frame = remote.probe.latest("/openral/cameras/front/image")
    assert (frame.width, frame.height, frame.encoding) == (128, 128, "rgb8")


def _wave_moves_the_servos(bus: RemoteBus, remote: Remote) -> None:
    seen = time.time()
    runner = openral(
        "rskill", "run", "--robot", "so101", "--policy", "wave", "-p", "amplitude=0.3",
        "-p", "period_s=2.0", "--duration", "4", "--domain-id", str(remote.domain),
    )  # fmt: skip
    _, err = runner.communicate(timeout=60)
    assert runner.returncode == 0, err
    written = bus.written("Goal_Position", seen)
    assert written, (bus.lines(seen - 1)[-5:], err)
    pan = [int(line.split()[3].split("=")[1]) for line in written]
    assert max(pan) - min(pan) > 0.25 * 4096 / (2 * np.pi)  # the wave swung the servo


def _three_point_goal(remote: Remote, node: Node) -> None:
    client = TrajectoryActionClient(node)
    try:
        start = joints_now(remote)
        points = [
            (1.0, [start[j] + 0.3 for j in ARM]),
            (2.0, [start[j] - 0.2 for j in ARM]),
            (3.0, [start[j] + 0.4 for j in ARM]),
        ]
        status, result, _ = client.run(goal(ARM, points, goal_tolerance=0.02, goal_time_s=1.0))
        assert status == SUCCEEDED, (result.error_code, result.error_string)
        reached = joints_now(remote)
        for joint, wanted in zip(ARM, points[-1][1], strict=True):
            assert reached[joint] == pytest.approx(wanted, abs=0.02)
    finally:
        client.destroy()


def _estop_release_and_reset(client: Node) -> None:
    assert call_trigger(client, "/openral/estop", 10.0).success
    reset = call_trigger(client, "/openral/reset", 10.0)
    assert not reset.success and "a real robot cannot be reset" in reset.message
    assert call_trigger(client, "/openral/release_estop", 10.0).success


def test_a_silent_motor_is_one_line_and_no_goal_follows(bus: RemoteBus) -> None:
    with remote_graph() as remote:
        process = deploy_real(bus.path, bus.calibration, remote.domain)
        try:
            _serving(remote)
            injected = time.time()
            assert bus.command("silent 3").startswith("ok")
            time.sleep(1.0)
            goals = bus.written("Goal_Position", injected + 0.025)
        finally:
            _, err = stop(process)
    latched = [line for line in err.splitlines() if "E-stop latched" in line]
    assert len(latched) == 1, err
    assert "motor 3 (elbow_flex) stopped answering" in latched[0]
    assert goals == []
