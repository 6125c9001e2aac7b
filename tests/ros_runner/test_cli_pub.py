"""``openral ros pub`` against a real rclpy subscriber: values become the message, the
count and rate hold, and every bad argument is one line with nothing sent."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from typing import Any

import pytest
from geometry_msgs.msg import Twist
from openral_cli.main import app
from openral_nodes.message_fill import MessageValueError, build_message, parse_values
from rclpy.node import Node
from sensor_msgs.msg import JointState
from typer.testing import CliRunner

from tests.ros_runner.conftest import DOMAIN_ID, RosHarness, wait_until

runner = CliRunner()
ENV = {"COLUMNS": "200", "ROS_DOMAIN_ID": str(DOMAIN_ID)}


def _listener(ros: RosHarness, topic: str = "/cmd_vel") -> tuple[list[Any], list[float]]:
    received: list[Any] = []
    arrivals: list[float] = []

    def keep(msg: Any) -> None:
        received.append(msg)
        arrivals.append(time.monotonic())

    node = ros.add(Node("pub_listener", context=ros.context))
    node.create_subscription(Twist, topic, keep, 50)
    return received, arrivals


def test_pub_sends_count_messages_with_the_values_at_the_rate(ros: RosHarness) -> None:
    received, arrivals = _listener(ros)
    args = [
        "ros",
        "pub",
        "/cmd_vel",
        "geometry_msgs/msg/Twist",
        "{linear: {x: 0.3}, angular: {z: -1}}",
    ]
    result = runner.invoke(app, [*args, "--count", "10", "--rate", "20"], env=ENV)
    assert result.exit_code == 0, result.output
    assert "published 10 geometry_msgs/msg/Twist on /cmd_vel at 20 Hz" in result.output
    assert wait_until(lambda: len(received) == 10)
    assert all(m.linear.x == 0.3 and m.angular.z == -1.0 and m.linear.y == 0.0 for m in received)
    assert 0.3 < arrivals[-1] - arrivals[0] < 1.0  # nine periods of 50 ms, loosely


@pytest.mark.parametrize(
    ("values", "message"),
    [
        (
            "{linear: {q: 1}}",
            "linear.q: not a field of geometry_msgs/msg/Vector3; its fields: x, y, z",
        ),
        ("{linear: {x: fast}}", "linear.x: expected a number, got 'fast'"),
        ("{linear: 3}", "linear: expected a mapping of geometry_msgs/Vector3's fields, got 3"),
        ("[1, 2]", "values: expected a mapping of field names"),
        ("{linear: {x: 1}", "values: "),
    ],
)
def test_bad_values_are_one_line_and_nothing_is_sent(
    ros: RosHarness, values: str, message: str
) -> None:
    received, _ = _listener(ros)
    result = runner.invoke(
        app, ["ros", "pub", "/cmd_vel", "geometry_msgs/msg/Twist", values], env=ENV
    )
    assert result.exit_code == 1
    assert message in str(result.exception) and "\n" not in str(result.exception)
    time.sleep(0.2)
    assert received == []


def test_a_type_openral_does_not_build_or_another_topics_type_is_refused(ros: RosHarness) -> None:
    _listener(ros)
    other = runner.invoke(
        app, ["ros", "pub", "/cmd_vel", "sensor_msgs/msg/JointState", "{}"], env=ENV
    )
    assert other.exit_code == 1
    assert "/cmd_vel carries geometry_msgs/msg/Twist" in str(other.exception)
    foreign = runner.invoke(app, ["ros", "pub", "/x", "os/msg/System", "{}"], env=ENV)
    assert foreign.exit_code == 1 and "openral does not decode" in str(foreign.exception)


def test_no_subscriber_is_an_error_after_the_timeout(ros: RosHarness) -> None:
    result = runner.invoke(
        app, ["ros", "pub", "/nobody", "geometry_msgs/msg/Twist", "--timeout", "0.3"], env=ENV
    )
    assert result.exit_code == 1
    assert "no subscriber on /nobody within 0.3 s; nothing sent" in str(result.exception)


def test_the_command_line_prints_a_bad_value_as_one_line() -> None:
    command = [sys.executable, "-m", "openral_cli.main", "ros", "pub", "/cmd_vel"]
    command += ["geometry_msgs/msg/Twist", "{linear: {x: fast}}"]
    done = subprocess.run(command, capture_output=True, text=True, env={**os.environ, **ENV})
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip() == "linear.x: expected a number, got 'fast'" or (
        done.stderr.count("\n") == 1 and "linear.x: expected a number, got 'fast'" in done.stderr
    )
    assert "Traceback" not in done.stderr


def test_values_fill_sequences_arrays_integers_and_strings() -> None:
    msg = build_message(
        JointState,
        parse_values("{name: [a, b], position: [1, 2.5], header: {frame_id: f, stamp: {sec: 3}}}"),
    )
    assert list(msg.name) == ["a", "b"] and list(msg.position) == [1.0, 2.5]
    assert msg.header.frame_id == "f" and msg.header.stamp.sec == 3
    for values, problem in [
        (
            "{header: {stamp: {sec: 3000000000}}}",
            "header.stamp.sec: expected a whole number from -2147483648 to 2147483647 (int32)",
        ),
        ("{name: [a, 2]}", "name[1]: expected text, got 2"),
        ("{position: 1}", "position: expected a list, got 1"),
        ("{a: &x [1, 2], b: *x, c: *x}", "a: not a field of sensor_msgs/msg/JointState"),
    ]:
        with pytest.raises(
            MessageValueError,
            match=problem.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)"),
        ):
            build_message(JointState, parse_values(values))
