"""``openral ros``: inspect a ROS 2 graph without ros2cli (which is not on PyPI).

Examples::

    openral ros topics --rate
    openral ros services
    openral ros actions
    openral ros nodes
    openral ros echo /joint_states --once
    openral ros snapshot /openral/cameras/agentview/image --out agentview.png
    openral ros pub /cmd_vel geometry_msgs/msg/Twist "{linear: {x: 0.3}}" --count 40 --rate 20
    openral ros call /openral/estop
    openral ros call /openral/release_estop std_srvs/srv/Trigger
    openral ros call /openral/reset
    openral ros call /some/switch std_srvs/srv/SetBool "{data: true}"
    openral ros tf
    openral ros tf hand --target link0
    openral ros reset

rclpy is imported only when a command runs, so the rest of the CLI works without the
``ros`` extra.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from openral_cli.console import err, out
from openral_cli.help_text import command_group
from openral_cli.ros_available import require_ros

if TYPE_CHECKING:
    from openral_nodes.topic_probe import Inbox
    from rclpy.node import Node

app = command_group(
    "Inspect the ROS 2 graph: topics, services, actions, nodes, messages, camera frames, TF; "
    "publish a message, call a service."
)

DomainId = Annotated[
    int | None,
    typer.Option(
        "--domain-id", min=0, max=232, help="ROS domain.", show_default="$ROS_DOMAIN_ID or 0"
    ),
]
DiscoveryWait = Annotated[
    float, typer.Option("--wait", min=0.0, help="Seconds to let discovery run first.")
]
Timeout = Annotated[
    float,
    typer.Option("--timeout", min=0.0, help="Seconds to wait for the topic, then for a message."),
]


@contextmanager
def _probe_node(domain_id: int | None, *, events: bool = False) -> Iterator[Node]:
    """A short-lived, spun node on its own rclpy context; Ctrl-C inside ends the command (0).
    ``events``: spun by rclpy's EventsExecutor (see :class:`~openral_nodes.runtime.Spinner`)."""
    from openral_nodes.runtime import Spinner, ros_session
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    # no ~/get_type_description service either: `ros services` would list it
    overrides = [Parameter("start_type_description_service", value=False)]  # type: ignore[no-untyped-call]
    with _quiet_ctrl_c(), ros_session(domain_id) as context:
        node = Node(
            f"openral_cli_{os.getpid()}",
            context=context,
            enable_rosout=False,
            start_parameter_services=False,
            parameter_overrides=overrides,
        )
        try:
            with Spinner(context, events=events) as spinner:
                spinner.add_node(node)
                yield node
        finally:
            node.destroy_node()  # type: ignore[no-untyped-call]


@contextmanager
def _quiet_ctrl_c() -> Iterator[None]:
    """Ctrl-C stops the command with exit code 0 and no traceback."""
    try:
        yield
    except KeyboardInterrupt:
        raise typer.Exit(0) from None


LATE_DISCOVERY_S = 3.0
"""How much longer ``topics`` (``services``, ``actions``, ``nodes``) may look after
``--wait`` while the graph is empty or still changing: FastDDS announces a participant
again every 3 s, so a peer that missed the first announcement (a loaded machine) shows up
within that [s]."""


@app.command("topics")
def topics(
    wait: DiscoveryWait = 2.0,
    rate: Annotated[bool, typer.Option("--rate", help="Measure each topic's rate.")] = False,
    window: Annotated[
        float, typer.Option("--window", min=0.1, help="Seconds to measure rates over.")
    ] = 2.0,
    all_topics: Annotated[
        bool,
        typer.Option(
            "--all", help="Include hidden topics: /rosout, /parameter_events, /_action/ ones."
        ),
    ] = False,
    domain_id: DomainId = None,
) -> None:
    """Table of the topics in the graph: name, type(s), publishers and (--rate) rate."""
    require_ros()
    from openral_core.errors import escaped
    from openral_nodes.topic_graph import settled_topics
    from openral_nodes.topic_probe import measure_rates
    from rich.table import Table

    with _probe_node(domain_id) as node:
        infos, waited = settled_topics(
            node, wait_s=wait, longest_s=wait + LATE_DISCOVERY_S, include_hidden=all_topics
        )
        rates = measure_rates(node, infos, window) if rate else {}
        domain = node.context.get_domain_id()
    if not infos:
        err.print(f"no topics on ROS_DOMAIN_ID={domain} after {waited:.1f} s", highlight=True)
        return
    table = Table(title=f"ROS_DOMAIN_ID={domain}")
    table.add_column("topic", no_wrap=True)
    table.add_column("type", overflow="fold")
    table.add_column("pubs", justify="right", no_wrap=True)
    if rate:
        table.add_column("Hz", justify="right", no_wrap=True)
    for info in infos:
        row = [info.name, ", ".join(map(escaped, info.types)), str(info.publishers)]
        if rate:
            hz = rates.get(info.name)
            row.append("-" if hz is None else f"{hz:.1f}")
        table.add_row(*row)
    out.print(table)


@app.command("echo")
def echo(
    topic: Annotated[str, typer.Argument(help="Topic name, e.g. /joint_states.")],
    once: Annotated[bool, typer.Option("--once", help="Print one message and exit.")] = False,
    timeout: Timeout = 5.0,
    domain_id: DomainId = None,
) -> None:
    """Print messages of TOPIC (any type in the graph); big arrays are summarised."""
    require_ros()
    from openral_nodes.topic_format import format_message
    from openral_nodes.topic_graph import wait_for_topic
    from openral_nodes.topic_probe import subscribe

    with _probe_node(domain_id) as node:
        info = wait_for_topic(node, topic, timeout)
        with subscribe(node, info) as inbox:
            msg = inbox.get(timeout)
            while True:
                out.print(format_message(msg))
                if once:
                    return
                out.print("---")
                msg = _next(inbox)


def _next(inbox: Inbox) -> Any:
    """Block until the inbox's next message, waking every second so Ctrl-C is noticed."""
    from openral_nodes.topic_probe import NoMessage

    while True:
        try:
            return inbox.get(1.0)
        except NoMessage:
            continue


@app.command("snapshot")
def snapshot(
    topic: Annotated[str, typer.Argument(help="A sensor_msgs/Image topic.")],
    out_file: Annotated[Path, typer.Option("--out", help="PNG file to write.")],
    timeout: Timeout = 5.0,
    domain_id: DomainId = None,
) -> None:
    """Save one frame of an Image topic (rgb8, bgr8 or mono8) as PNG; a depth image (32FC1
    or 16UC1) is colour-mapped, near warm and far cool, no reading black."""
    require_ros()
    from openral_core.errors import OpenralError, escaped
    from openral_mujoco.png import write_png
    from openral_nodes.topic_codec import DEPTH_ENCODINGS, depth_colours, depth_metres, image_to_rgb
    from openral_nodes.topic_format import sensor_summary
    from openral_nodes.topic_graph import wait_for_topic
    from openral_nodes.topic_probe import subscribe

    with _probe_node(domain_id) as node:
        info = wait_for_topic(node, topic, timeout)
        if "sensor_msgs/msg/Image" not in info.types:
            raise OpenralError(
                f"{info.name} carries {', '.join(map(escaped, info.types))}, "
                "not sensor_msgs/msg/Image"
            )
        with subscribe(node, info) as inbox:
            msg = inbox.get(timeout)
    depth = msg.encoding in DEPTH_ENCODINGS
    rgb = depth_colours(depth_metres(msg)) if depth else image_to_rgb(msg)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    write_png(out_file, rgb)
    size = f"{rgb.shape[1]}x{rgb.shape[0]}"
    what = f"{sensor_summary(msg)}, colour-mapped" if depth else f"{size} {msg.encoding}"
    out.print(
        f"wrote {out_file} ({what}, frame {escaped(msg.header.frame_id) or '-'}) from {info.name}",
        markup=False,
    )


@app.command("pub")
def pub(
    topic: Annotated[str, typer.Argument(help="Topic name, e.g. /cmd_vel.")],
    type_name: Annotated[str, typer.Argument(help="Message type, e.g. geometry_msgs/msg/Twist.")],
    values: Annotated[
        str, typer.Argument(help="Field values as YAML, e.g. '{linear: {x: 0.3}}'.")
    ] = "{}",
    count: Annotated[int, typer.Option("--count", min=1, help="Messages to publish.")] = 1,
    rate: Annotated[
        float, typer.Option("--rate", min=0.01, max=1000.0, help="Messages per second.")
    ] = 10.0,
    timeout: Timeout = 5.0,
    domain_id: DomainId = None,
) -> None:
    """Publish COUNT messages of TYPE with VALUES on TOPIC at RATE, once a subscriber listens.

    Only types of the packages openral installs are built; VALUES is read like a manifest
    (no aliases, tags or deep nesting) and checked field by field before anything is sent.
    """
    require_ros()
    from openral_core.errors import OpenralError, escaped
    from openral_nodes.message_fill import build_message, parse_values
    from openral_nodes.topic_graph import graph_topics, message_class, topic_name

    name = topic_name(topic)
    msg = build_message(message_class(type_name, name), parse_values(values))
    with _probe_node(domain_id) as node:
        publisher = node.create_publisher(type(msg), name, 10)
        deadline = time.monotonic() + timeout
        while publisher.get_subscription_count() == 0:  # a peer of another type never matches
            types = {info.name: info.types for info in graph_topics(node)}.get(name, ())
            if any(other != type_name for other in types):
                shown = ", ".join(map(escaped, types))
                raise OpenralError(f"{name} carries {shown}, not {escaped(type_name)}")
            if time.monotonic() >= deadline:
                raise OpenralError(f"no subscriber on {name} within {timeout:g} s; nothing sent")
            time.sleep(0.05)
        start = time.monotonic()
        for index in range(count):
            time.sleep(max(0.0, start + index / rate - time.monotonic()))
            publisher.publish(msg)
        time.sleep(0.2)  # let the last message leave before the node goes
    out.print(f"published {count} {type_name} on {name} at {rate:g} Hz", markup=False)


ServiceTimeout = Annotated[
    float,
    typer.Option("--timeout", min=0.0, help="Seconds to wait for the service, then its answer."),
]
"""``--timeout`` of the commands that call a service (each sets its own default)."""


@app.command("call")
def call(
    service: Annotated[str, typer.Argument(help="Service name, e.g. /openral/estop.")],
    type_name: Annotated[
        str | None,
        typer.Argument(
            metavar="TYPE",
            help="Service type, e.g. std_srvs/srv/SetBool.",
            show_default="the graph's",
        ),
    ] = None,
    values: Annotated[
        str, typer.Argument(help="Request fields as YAML, e.g. '{data: true}'.")
    ] = "{}",
    timeout: ServiceTimeout = 5.0,
    domain_id: DomainId = None,
) -> None:
    """Call SERVICE with a request of VALUES and print the response; exit 1 when it answers
    `success: false`.

    TYPE is found in the graph when left out (VALUES may then come second). Only types of
    the packages openral installs are built; VALUES is read like `ros pub` reads them.

    Examples:

        openral ros call /openral/estop
        openral ros call /openral/release_estop std_srvs/srv/Trigger
        openral ros call /openral/reset
        openral ros call /some/switch std_srvs/srv/SetBool "{data: true}"
    """
    require_ros()
    from openral_core.errors import OpenralError, escaped
    from openral_nodes.message_fill import parse_values
    from openral_nodes.service_call import call_service, checked_request
    from openral_nodes.topic_format import format_message

    if type_name is not None and values == "{}" and _looks_like_values(type_name):
        values, type_name = type_name, None  # `call SERVICE VALUES`: the type is the graph's
    request = parse_values(values)
    checked_request(service, type_name, request)  # a bad argument fails before any ROS setup
    with _probe_node(domain_id) as node:
        answer = call_service(node, service, type_name, request, timeout)
    out.print(f"# {answer.service}: {escaped(answer.type_name)}")
    out.print(format_message(answer.response) or "(empty response)")
    if answer.failed:
        raise OpenralError(f"{answer.service} answered success: false")


def _looks_like_values(text: str) -> bool:
    """True for request text given where the type goes: a type has no ``{``, ``:`` or space."""
    return not text.strip() or any(mark in text for mark in "{: ")


@app.command("tf")
def tf(
    frame: Annotated[
        str | None,
        typer.Argument(help="Frame to locate; the whole tree when left out.", show_default=False),
    ] = None,
    target: Annotated[
        str | None,
        typer.Option("--target", help="Frame to express FRAME in.", show_default="the root"),
    ] = None,
    timeout: Annotated[
        float,
        typer.Option(
            "--timeout",
            min=0.0,
            help="Seconds to listen to /tf and /tf_static once the first transform arrives "
            "(awaited 3 s longer).",
        ),
    ] = 3.0,
    domain_id: DomainId = None,
) -> None:
    """Print the TF tree, or where FRAME is.

    Without FRAME: every frame below the root, indented under its parent, with `static` or
    the rate it was seen at [Hz]. With FRAME: its pose in the root frame (or TARGET), composed
    from the latest transform of each link: translation [m], quaternion (x y z w),
    roll/pitch/yaw [rad] and stamp [s]. An unknown frame names the closest known ones.

    Examples:

        openral ros tf
        openral ros tf hand
        openral ros tf hand --target link0
    """
    require_ros()
    from openral_cli.commands.ros_tf import gather, report

    with _probe_node(domain_id) as node:
        buffer = gather(node, timeout, frame, target)
        domain = node.context.get_domain_id()
    for text in report(buffer, frame, target, timeout, domain):
        out.print(text)


@app.command("reset")
def reset(
    timeout: ServiceTimeout = 10.0,
    domain_id: DomainId = None,
) -> None:
    """Reset the simulated scene through ``/openral/reset``: its seed, the start pose and
    every object, while the graph keeps running (the E-stop stays as it is)."""
    require_ros()
    from openral_bridge.topics import RESET
    from openral_core.errors import OpenralError
    from openral_nodes.service_call import call_trigger

    with _probe_node(domain_id) as node:
        answer = call_trigger(node, RESET, timeout)
    if not answer.success:
        raise OpenralError(f"{RESET}: {answer.message}")
    out.print(answer.message, markup=False)
