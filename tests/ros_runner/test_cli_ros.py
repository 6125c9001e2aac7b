"""``openral ros topics/echo/snapshot`` against a fake deploy-sim graph on real rclpy."""

from __future__ import annotations

import os
import re
import signal
import struct
import subprocess
import sys
import threading
import zlib
from pathlib import Path

import numpy as np
from openral_cli.main import app
from typer.testing import CliRunner

from tests.ros_runner.conftest import COLOURS, DOMAIN_ID, FRAME_SHAPE, RosHarness, wait_until

runner = CliRunner()
WIDE = {"COLUMNS": "200", "ROS_DOMAIN_ID": str(DOMAIN_ID)}


def read_png(path: Path) -> np.ndarray:
    """Pixels of an 8-bit RGB PNG whose rows all use filter 0 (as openral_mujoco.png writes)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, size = 8, b"", (0, 0)
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            size = struct.unpack(">II", body[:8])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height = size
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, 1 + 3 * width)
    assert not rows[:, 0].any()
    return rows[:, 1:].reshape(height, width, 3)


def test_topics_lists_names_types_publishers_and_rates(ros: RosHarness) -> None:
    ros.fake_graph()
    result = runner.invoke(
        app, ["ros", "topics", "--wait", "3", "--rate", "--window", "2"], env=WIDE
    )
    assert result.exit_code == 0, result.output
    rows = {
        cells[1]: cells[2:5]
        for line in result.output.splitlines()
        if len(cells := [c.strip() for c in line.split("│")]) == 6
    }
    assert "/rosout" not in rows
    image = rows["/openral/cameras/agentview/image"]
    assert image[:2] == ["sensor_msgs/msg/Image", "1"]
    assert 5.0 < float(image[2]) < 15.0, image  # published at 10 Hz; loose for a loaded host
    assert rows["/joint_states"][:2] == ["sensor_msgs/msg/JointState", "1"]
    assert rows["/openral/safe_action"][1] == "0"  # subscribed to, nobody publishes
    assert rows["/openral/action_spec"][2] == "-"  # latched, published once: no rate


def test_echo_once_prints_one_readable_message(ros: RosHarness) -> None:
    ros.fake_graph()
    result = runner.invoke(app, ["ros", "echo", "joint_states", "--once"], env=WIDE)
    assert result.exit_code == 0, result.output
    assert "name: [panda_joint1, panda_joint2," in result.output
    assert "position: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]" in result.output
    assert "---" not in result.output


def test_echo_receives_the_latched_action_spec_and_summarises_images(ros: RosHarness) -> None:
    ros.fake_graph()
    spec = runner.invoke(app, ["ros", "echo", "/openral/action_spec", "--once"], env=WIDE)
    assert spec.exit_code == 0, spec.output
    assert "position: [0.0, -0.4, 0.0, -2.2, 0.0, 1.9, 0.8, 0.04]" in spec.output
    image = runner.invoke(app, ["ros", "echo", "/openral/cameras/wrist/image", "--once"], env=WIDE)
    assert image.exit_code == 0, image.output
    assert "frame_id: wrist" in image.output
    assert f"data: <{FRAME_SHAPE[0] * FRAME_SHAPE[1] * 3} values uint8: min 10, max 220" in (
        image.output
    )


def test_snapshot_writes_the_camera_frame_as_png(ros: RosHarness, tmp_path: Path) -> None:
    ros.fake_graph()
    out = tmp_path / "shots" / "agentview.png"
    result = runner.invoke(
        app, ["ros", "snapshot", "/openral/cameras/agentview/image", "--out", str(out)], env=WIDE
    )
    assert result.exit_code == 0, result.output
    assert f"wrote {out} (64x48 rgb8, frame agentview)" in result.output
    pixels = read_png(out)
    assert pixels.shape == (*FRAME_SHAPE, 3)
    assert (pixels == COLOURS["agentview"]).all()


def test_snapshot_refuses_a_topic_that_is_not_an_image(ros: RosHarness, tmp_path: Path) -> None:
    ros.fake_graph()
    result = runner.invoke(
        app, ["ros", "snapshot", "/joint_states", "--out", str(tmp_path / "x.png")], env=WIDE
    )
    assert result.exit_code == 1
    assert "/joint_states carries sensor_msgs/msg/JointState, not sensor_msgs/msg/Image" in str(
        result.exception
    )
    assert not (tmp_path / "x.png").exists()


def test_echo_of_a_missing_topic_exits_1_naming_the_topics_that_exist(ros: RosHarness) -> None:
    ros.fake_graph()
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "openral_cli.main",
            *["ros", "echo", "/camera/nope", "--once", "--timeout", "4"],
        ],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "ROS_DOMAIN_ID": str(DOMAIN_ID), "COLUMNS": "300"},
    )
    assert result.returncode == 1, result.stdout
    message = " ".join(result.stderr.split())
    assert message.startswith(
        f"error: topic /camera/nope did not appear within 4 s on ROS_DOMAIN_ID={DOMAIN_ID}; "
        "topics in the graph: "
    )
    for topic in ("/joint_states", "/openral/cameras/agentview/image", "/openral/action_spec"):
        assert topic in message
    assert "Traceback" not in result.stderr


def test_echo_streams_until_ctrl_c_then_exits_0(ros: RosHarness) -> None:
    ros.fake_graph()
    command = [sys.executable, "-m", "openral_cli.main", "ros", "echo", "/joint_states"]
    process = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "ROS_DOMAIN_ID": str(DOMAIN_ID)},
    )
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(process.stdout.readline, "")))
    reader.start()
    try:
        assert wait_until(lambda: lines.count("---\n") >= 2, timeout_s=30.0), lines
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
        reader.join()
    assert process.returncode == 0, stderr
    assert "Traceback" not in stderr
    assert sum(line.startswith("name: [panda_joint1") for line in lines) >= 2


def test_topics_on_an_empty_graph_keeps_looking_for_late_peers_then_says_so() -> None:
    from openral_cli.commands.ros import LATE_DISCOVERY_S
    from openral_nodes.runtime import claim_domain_id

    empty = claim_domain_id()
    result = runner.invoke(app, ["ros", "topics", "--wait", "0", "--domain-id", str(empty)])
    assert result.exit_code == 0
    waited = re.search(rf"no topics on ROS_DOMAIN_ID={empty} after ([0-9.]+) s", result.output)
    assert waited is not None, result.output  # it looked for the whole late-discovery window
    assert LATE_DISCOVERY_S <= float(waited.group(1)) < LATE_DISCOVERY_S + 1.0, result.output
