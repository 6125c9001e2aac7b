"""``openral ros`` never imports a module a peer names, and refuses bad topic names up front.

A topic's type string comes from whichever peer advertises it. Only the packages in
``DECODABLE_PACKAGES`` are ever imported; anything else is one error line and exit 1.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from types import ModuleType

import pytest
from control_msgs.action import FollowJointTrajectory
from openral_nodes.topic_graph import (
    DECODABLE_PACKAGES,
    MessageTypeError,
    TopicNameError,
    message_class,
    topic_name,
)
from rclpy.node import Node
from sensor_msgs.msg import Image
from unique_identifier_msgs.msg import UUID

from tests.ros_runner.conftest import RosHarness
from tests.ros_runner.conftest import run_cli as run_entry_point

HOSTILE_TYPES = {
    "os/msg/system": "which openral does not decode; decodable packages: action_msgs, builtin",
    "subprocess/msg/Popen": "which openral does not decode",
    "evil_pkg/msg/Thing": "which openral does not decode",
    "unique_identifier_msgs/msg/UUID": "which openral does not decode",  # installed, not listed
    "evil_pkg/action/Thing_FeedbackMessage": "which openral does not decode",
    "sensor_msgs/action/__class___FeedbackMessage": "'__class___FeedbackMessage' is not a",
    "sensor_msgs/action/Image": "'Image' is not a message name",  # only an action's feedback
    "control_msgs/action/FollowJointTrajectory_SendGoal": "is not a message name",
    "../x/msg/Y": "which is not a message type (expected pkg/msg/Name)",
    "sensor_msgs/msg/Image/x": "which is not a message type",
    "sensor_msgs/srv/Image": "which is not a message type",
    "sensor_msgs/msg/__class__": "'__class__' is not a message name",
    "sensor_msgs/msg/__builtins__": "'__builtins__' is not a message name",
    "sensor_msgs/msg/np": "'np' is not a message name",
    "sensor_msgs/msg/": "'' is not a message name",
    "x\x1b[2J/msg/Y": "has type x\\x1b[2J/msg/Y, which openral",  # shown escaped
}


@pytest.fixture
def imports(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Every name passed to ``importlib.import_module`` while the test runs."""
    names: list[str] = []
    real = importlib.import_module

    def spy(name: str, package: str | None = None) -> ModuleType:
        names.append(name)
        return real(name, package)

    monkeypatch.setattr(importlib, "import_module", spy)
    return names


@pytest.mark.parametrize("type_name", list(HOSTILE_TYPES))
def test_a_hostile_type_is_refused_without_importing_anything(
    imports: list[str], type_name: str
) -> None:
    before = set(sys.modules)
    with pytest.raises(MessageTypeError) as error:
        message_class(type_name, "/x")
    message = str(error.value)
    assert message.startswith("topic /x has type "), message
    assert HOSTILE_TYPES[type_name] in message
    assert imports == []
    assert set(sys.modules) == before


def test_an_allowed_type_is_imported_from_its_package_only(imports: list[str]) -> None:
    assert message_class("sensor_msgs/msg/Image", "/cam") is Image
    with pytest.raises(MessageTypeError, match="sensor_msgs/msg/Nope, which sensor_msgs does not"):
        message_class("sensor_msgs/msg/Nope", "/cam")
    assert imports == ["sensor_msgs.msg", "sensor_msgs.msg"]
    assert "unique_identifier_msgs" not in DECODABLE_PACKAGES
    assert {"sensor_msgs", "std_msgs", "rcl_interfaces"} <= set(DECODABLE_PACKAGES)


def test_an_action_feedback_type_is_the_actions_own_feedback_message(imports: list[str]) -> None:
    feedback = "control_msgs/action/FollowJointTrajectory_FeedbackMessage"
    assert (
        message_class(feedback, "/f/_action/feedback") is FollowJointTrajectory.Impl.FeedbackMessage
    )
    with pytest.raises(MessageTypeError, match="Nope_FeedbackMessage, which control_msgs does not"):
        message_class("control_msgs/action/Nope_FeedbackMessage", "/f")
    assert imports == ["control_msgs.action", "control_msgs.action"]


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("/[x]", "must not contain characters other than alphanumerics, '_', or '/'"),
        ("/a//b", "must not contain repeated '/'"),
        ("/1st", "must not have a token that starts with a number"),
        ("/x\x1b[31m", "must not contain characters other than alphanumerics, '_', or '/'"),
    ],
)
def test_invalid_topic_names_are_one_line_errors(name: str, reason: str) -> None:
    with pytest.raises(TopicNameError) as error:
        topic_name(name)
    shown = name.replace("\x1b", "\\x1b")  # escaped, never sent to the terminal raw
    assert str(error.value) == f"{shown} is not a valid ROS topic name: topic name {reason}"
    assert topic_name("joint_states") == "/joint_states"


def run_cli(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str
) -> tuple[int, str]:
    """``openral ARGS`` through the entry point: exit code and all it printed."""
    code, out, err = run_entry_point(monkeypatch, capsys, *args)
    return code, out + err


def test_echo_of_a_peer_type_outside_the_allow_list_is_one_line_and_exit_1(
    ros: RosHarness,
    imports: list[str],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    peer = ros.add(Node("hostile_peer", context=ros.context))
    peer.create_publisher(UUID, "/hostile/status", 1)
    code, output = run_cli(monkeypatch, capsys, "ros", "echo", "/hostile/status", "--once")
    assert code == 1, output
    assert output == (
        "error: topic /hostile/status has type unique_identifier_msgs/msg/UUID, which openral "
        f"does not decode; decodable packages: {', '.join(DECODABLE_PACKAGES)}\n"
    )
    assert not any(name.startswith("unique_identifier_msgs") for name in imports), imports


def test_snapshot_writes_to_a_bracketed_path_and_names_it_verbatim(
    ros: RosHarness,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    ros.fake_graph()
    out = tmp_path / "[/x]" / "[bold]:smile:.png"
    topic = "/openral/cameras/wrist/image"
    code, output = run_cli(monkeypatch, capsys, "ros", "snapshot", topic, "--out", str(out))
    assert code == 0, output
    assert f"wrote {out} (64x48 rgb8, frame wrist) from {topic}" in output
    assert out.is_file()
