"""What ``deploy sim`` and ``deploy real`` print once the graph is up: the published topics
in a table (fits 80 columns), then what the graph takes (actions, trajectories, the
controllers, the E-stop), every name under the graph's namespace."""

from __future__ import annotations

from typing import TYPE_CHECKING

from openral_cli.console import out

if TYPE_CHECKING:
    from openral_nodes.manifest_node import ManifestLifecycleNode


def print_interfaces(node: ManifestLifecycleNode, title: str) -> None:
    """Print what ``node`` (active) offers; ``title`` may hold ``{robot}``."""
    from rich import box
    from rich.table import Table

    robot = node.description.name if node.description is not None else "?"
    table = Table(title=title.format(robot=robot), box=box.SIMPLE_HEAD, pad_edge=False)
    for column in ("published topic", "type", "rate"):
        table.add_column(column, overflow="fold")
    for topic in node.topics():
        rate = f"{topic.rate_hz:g} Hz {topic.when}" if topic.rate_hz else topic.when or "latched"
        table.add_row(topic.name, topic.type, rate.strip())
    out.print(table, soft_wrap=False)
    for label, line in _inputs(node):
        out.print(f"{label:<10}{line}", soft_wrap=False, markup=False)
    out.print(
        "running; stop with Ctrl-C. In a second terminal: openral ros topics", soft_wrap=False
    )


def _inputs(node: ManifestLifecycleNode) -> list[tuple[str, str]]:
    """(label, line) of each input of the graph."""
    from openral_bridge import topics as t
    from openral_nodes.graph_names import graph_name

    def name(topic: str) -> str:
        return graph_name(node, topic)

    names, _ = node.action_layout()
    rows = [
        (
            "actions:",
            f"{name(t.SAFE_ACTION)} (std_msgs/msg/Float64MultiArray, "
            f"{len(names)} values: {', '.join(names)})",
        )
    ]
    commands = node.commands
    if commands is not None and commands.follows_trajectories:
        kind = "trajectory_msgs/msg/JointTrajectory, joints by manifest name"
        rows.append(("", f"{name(t.JOINT_TRAJECTORY)}, {name(t.JTC_JOINT_TRAJECTORY)} ({kind})"))
        kind = "control_msgs/action/FollowJointTrajectory"
        rows.append(("", f"{name(t.FOLLOW_JOINT_TRAJECTORY)} ({kind})"))
    bridge = node.bridge
    if bridge is not None and bridge.ee is not None:
        kind = f"geometry_msgs/msg/PoseStamped, the TCP in {bridge.ee.follower.base_frame}"
        rows.append(("", f"{name(t.EE_TARGET)} ({kind})"))
    if commands is not None and commands.surface.gripper is not None:
        axis = commands.surface.gripper.axis
        kind = f"control_msgs/action/GripperCommand, {axis.joint} {list(axis.limits)}"
        rows.append(("gripper:", f"{name(t.GRIPPER_COMMAND)} ({kind})"))
    manager = commands.surface.manager if commands is not None else None
    if manager is not None:
        services = "list_controllers, list_hardware_interfaces, switch_controller"
        rows.append(("control:", f"{name(t.CONTROLLER_MANAGER)}/{{{services}}}"))
        rows.append(("", f"controllers: {', '.join(manager.controllers)}"))
    if bridge is not None and bridge.base is not None:
        rows.append(("base:", f"{name(t.CMD_VEL)} (geometry_msgs/msg/Twist, base frame)"))
    rows.append(("E-stop:", f"{name(t.ESTOP)}, {name(t.RELEASE_ESTOP)} (std_srvs/srv/Trigger)"))
    if node.loop is not None and node.hal is not None and not node.hal.is_real:
        rows.append(("reset:", f"{name(t.RESET)} (std_srvs/srv/Trigger)"))
    view = bridge.view if bridge is not None else None
    if view is not None:
        rows.append(("view:", view.feed.view.ports.url))
    return rows
