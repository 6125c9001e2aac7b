"""``openral ros services/actions/nodes`` and ``ros echo`` of an action's hidden topics,
against a real rclpy peer offering a std_srvs/Trigger service and a FollowJointTrajectory
action (one goal executing, its feedback published at 10 Hz)."""

from __future__ import annotations

import re
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import pytest
from control_msgs.action import FollowJointTrajectory
from openral_cli.main import app
from openral_nodes.graph_listing import Interface, actions_of
from openral_nodes.runtime import Spinner
from rclpy.action import ActionClient, ActionServer, get_action_names_and_types
from rclpy.action.server import ServerGoalHandle
from rclpy.node import Node
from std_srvs.srv import Trigger
from typer.testing import CliRunner

from tests.ros_runner.conftest import DOMAIN_ID, RosHarness, wait_until

runner = CliRunner()
WIDE = {"COLUMNS": "200", "ROS_DOMAIN_ID": str(DOMAIN_ID)}
NAMESPACE = "/graph_test"
ACTION = f"{NAMESPACE}/follow"
FJT = "control_msgs/action/FollowJointTrajectory"
HIDDEN_SERVICES = {
    f"{ACTION}/_action/send_goal": f"{FJT}_SendGoal",
    f"{ACTION}/_action/get_result": f"{FJT}_GetResult",
    f"{ACTION}/_action/cancel_goal": "action_msgs/srv/CancelGoal",
}


@dataclass
class Peer:
    """The peer's node and the stop signal of its executing goal."""

    node: Node
    stop: threading.Event


def _execute(stop: threading.Event) -> Callable[[ServerGoalHandle], object]:
    def execute(goal: ServerGoalHandle) -> FollowJointTrajectory.Result:
        feedback = FollowJointTrajectory.Feedback(joint_names=["graph_joint"])
        while not stop.wait(0.1):
            goal.publish_feedback(feedback)
        goal.abort()
        return FollowJointTrajectory.Result()

    return execute


@pytest.fixture
def peer(ros: RosHarness) -> Iterator[Peer]:
    """A Trigger service and an action executing one goal (on a spinner of its own, which
    the goal's loop occupies), a client that sent it and a hidden node."""
    stop = threading.Event()
    node = Node("graph_peer", namespace=NAMESPACE, context=ros.context)
    node.create_service(Trigger, f"{NAMESPACE}/trigger", lambda _request, response: response)
    server = ActionServer(node, FollowJointTrajectory, ACTION, _execute(stop))
    spinner = Spinner(ros.context)
    spinner.add_node(node)
    spinner.start()
    client_node = ros.add(Node("graph_client", context=ros.context))
    ros.add(Node("_hidden_peer", context=ros.context))
    client = ActionClient(client_node, FollowJointTrajectory, ACTION)
    try:
        assert client.wait_for_server(timeout_sec=20.0)
        sent = client.send_goal_async(FollowJointTrajectory.Goal())
        assert wait_until(sent.done, timeout_s=20.0) and sent.result().accepted
        yield Peer(node, stop)
    finally:
        stop.set()
        spinner.stop()
        client.destroy()
        server.destroy()
        node.destroy_node()


def table(output: str) -> dict[str, str]:
    """First column → second column of a two-column table."""
    return {
        cells[1]: cells[2]
        for line in output.splitlines()
        if len(cells := [c.strip() for c in line.split("│")]) == 4
    }


def test_services_lists_names_and_types_and_the_hidden_ones_only_with_all(peer: Peer) -> None:
    result = runner.invoke(app, ["ros", "services"], env=WIDE)
    assert result.exit_code == 0, result.output
    shown = table(result.output)
    assert shown[f"{NAMESPACE}/trigger"] == "std_srvs/srv/Trigger"
    assert shown[f"{NAMESPACE}/graph_peer/get_parameters"] == "rcl_interfaces/srv/GetParameters"
    assert not any("/_" in name for name in shown), shown  # actions' and _hidden_peer's
    assert not any("openral_cli_" in name for name in shown), shown  # the command's own node
    every = runner.invoke(app, ["ros", "services", "--all"], env=WIDE)
    assert every.exit_code == 0, every.output
    listed = table(every.output)
    assert HIDDEN_SERVICES.items() <= listed.items(), listed
    assert "/_hidden_peer/get_parameters" in listed
    assert set(listed) - set(shown) == {name for name in listed if "/_" in name}, (
        "--all adds exactly the hidden ones"
    )


def test_actions_lists_the_action_and_its_type_as_rclpy_does(ros: RosHarness, peer: Peer) -> None:
    result = runner.invoke(app, ["ros", "actions"], env=WIDE)
    assert result.exit_code == 0, result.output
    assert table(result.output) == {ACTION: FJT}
    assert get_action_names_and_types(peer.node) == [(ACTION, [FJT])]  # rcl_action's view


def test_nodes_lists_full_names_and_namespaces_and_hidden_ones_only_with_all(
    peer: Peer,
) -> None:
    result = runner.invoke(app, ["ros", "nodes"], env=WIDE)
    assert result.exit_code == 0, result.output
    assert table(result.output) == {
        "/graph_client": "/",
        f"{NAMESPACE}/graph_peer": NAMESPACE,
    }  # neither _hidden_peer nor the command's own node
    every = runner.invoke(app, ["ros", "nodes", "--all"], env=WIDE)
    assert every.exit_code == 0, every.output
    assert table(every.output) == {
        "/_hidden_peer": "/",
        "/graph_client": "/",
        f"{NAMESPACE}/graph_peer": NAMESPACE,
    }


def test_echo_prints_an_actions_hidden_status_and_feedback(peer: Peer) -> None:
    status = runner.invoke(
        app, ["ros", "echo", f"{ACTION}/_action/status", "--once", "--timeout", "15"], env=WIDE
    )
    assert status.exit_code == 0, status.output
    assert "status_list:\n- goal_info:" in status.output
    assert "  status: 2" in status.output  # STATUS_EXECUTING, latched
    feedback = runner.invoke(
        app, ["ros", "echo", f"{ACTION}/_action/feedback", "--once", "--timeout", "15"], env=WIDE
    )
    assert feedback.exit_code == 0, feedback.output
    assert "goal_id:\n  uuid: [" in feedback.output
    assert "  joint_names: [graph_joint]" in feedback.output


def test_an_empty_graph_has_no_nodes_or_services_not_even_the_commands_own() -> None:
    from openral_cli.commands.ros import LATE_DISCOVERY_S
    from openral_nodes.runtime import claim_domain_id

    empty = str(claim_domain_id())
    for command in ("nodes", "services"):
        args = ["ros", command, "--all", "--wait", "0", "--domain-id", empty]
        result = runner.invoke(app, args)
        assert result.exit_code == 0, result.output
        waited = re.search(
            rf"no {command} on ROS_DOMAIN_ID={empty} after ([0-9.]+) s", result.output
        )
        assert waited is not None, result.output  # it looked for the whole late-discovery window
        assert float(waited.group(1)) >= LATE_DISCOVERY_S, result.output


def test_actions_come_from_feedback_topics_of_action_feedback_types() -> None:
    feedback = "control_msgs/action/FollowJointTrajectory_FeedbackMessage"
    topics = [
        ("/b/_action/feedback", [feedback]),
        ("/b/_action/status", ["action_msgs/msg/GoalStatusArray"]),
        ("/a/_action/feedback", ["my_pkg/action/Fibonacci_FeedbackMessage"]),
        ("/not_action/_action/feedback", ["std_msgs/msg/String"]),  # not a feedback type
        ("/feedback", [feedback]),  # not under _action/
        ("/c/_action/feedback", ["x/action/__class___FeedbackMessage"]),
    ]
    assert actions_of(topics) == (
        Interface("/a", ("my_pkg/action/Fibonacci",)),
        Interface("/b", (FJT,)),
    )
