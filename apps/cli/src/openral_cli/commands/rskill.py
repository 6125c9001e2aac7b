"""``openral rskill``: run a policy against a live openral ROS graph.

Example (with ``openral deploy sim`` running in another terminal)::

    openral rskill run --robot franka_panda --policy wave --duration 10
    openral rskill run --robot franka_panda -p amplitude=0.3 -p action_slots=panda_joint1
    openral rskill trajectory --move panda_joint1=0.5 --move panda_joint4=0.5 --relative

The runner realigns camera frames to VLA slots, calls the policy at ``--rate`` and
publishes on ``/openral/safe_action``. It exits 0 on Ctrl-C, SIGTERM or after
``--duration``; 1 with one message when it aborts (e.g. a camera slot the policy needs
never delivered frames).
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import TYPE_CHECKING, Annotated

import typer

from openral_cli.console import line, out, progress, status
from openral_cli.help_text import PARAM_HELP, command_group
from openral_cli.namespace_option import Namespace, checked
from openral_cli.ros_available import require_ros

if TYPE_CHECKING:
    from openral_nodes.rskill_runner import RskillRunnerNode
    from openral_nodes.trajectory_sender import TrajectoryReport

app = command_group("Run robot skills (policies) on the ROS graph.")

DomainId = Annotated[
    int | None,
    typer.Option("--domain-id", min=0, max=232, help="ROS domain.", show_default="$ROS_DOMAIN_ID"),
]
STATUS_PERIOD_S = 0.2
"""How often the status line refreshes [s]."""


@app.command("run")
def run(
    robot: Annotated[str, typer.Option("--robot", help="Robot id (folder under robots/).")],
    policy: Annotated[str, typer.Option("--policy", help="Built-in policy name.")] = "wave",
    params: Annotated[
        list[str] | None,
        typer.Option("--param", "-p", help=PARAM_HELP),
    ] = None,
    rate: Annotated[float, typer.Option("--rate", min=0.1, help="Actions per second.")] = 10.0,
    duration: Annotated[
        float | None, typer.Option("--duration", min=0.0, help="Stop after this many seconds.")
    ] = None,
    frame_timeout: Annotated[
        float,
        typer.Option("--frame-timeout", min=0.1, help="Seconds a required input may be missing."),
    ] = 5.0,
    domain_id: DomainId = None,
    namespace: Namespace = "",
) -> None:
    """Run POLICY for ROBOT: camera frames by VLA slot in, /openral/safe_action out."""
    require_ros()
    from openral_nodes.rskill_runner import RskillRunnerNode, runner_parameters
    from openral_nodes.runtime import Spinner, ros_session

    overrides = runner_parameters(
        robot,
        policy=policy,
        policy_params=params or [],
        rate_hz=rate,
        frame_timeout_s=frame_timeout,
    )
    # The node logs an abort too; this command reports it itself, as the one message.
    with ros_session(domain_id, ["--ros-args", "--disable-stdout-logs"]) as context:
        node = RskillRunnerNode(
            context=context, parameter_overrides=overrides, namespace=checked(namespace)
        )
        try:
            with Spinner(context) as spinner, _sigterm_as_interrupt():
                spinner.add_node(node)
                elapsed = _watch(node, policy, duration)
        finally:
            node.destroy_node()  # type: ignore[no-untyped-call]
    if node.abort_error is not None:
        raise node.abort_error
    out.print(
        f"{policy} on {node.robot}: {node.status.actions} action(s) on /openral/safe_action "
        f"in {elapsed:.1f} s ({_fed_routes(node) or 'no cameras'})"
    )


def _fed_routes(node: RskillRunnerNode) -> str:
    """``slot <- sensor`` for the slots that had frames at the runner's last tick.

    The manifest's slot table names every camera the robot has; a scene renders only those
    in its ``cameras`` list, so a slot whose camera the scene leaves out never gets a frame
    and is not listed.
    """
    fed = set(node.status.seen_slots)
    return ", ".join(f"{e.slot} <- {e.sensor}" for e in node.slot_table if e.slot in fed)


def _watch(node: RskillRunnerNode, policy: str, duration: float | None) -> float:
    """Show the runner's status until it aborts, ``duration`` passes or Ctrl-C; the seconds run."""
    start = time.monotonic()
    try:
        with status("starting") as shown:
            while node.abort_error is None:
                elapsed = time.monotonic() - start
                if duration is not None and elapsed >= duration:
                    break
                state = node.status
                shown.update(
                    line(
                        f"{policy} on {node.robot}: {state.state} · slots "
                        f"({', '.join(state.seen_slots)}) · {state.actions} action(s)"
                    )
                )
                time.sleep(STATUS_PERIOD_S)
    except KeyboardInterrupt:
        pass
    return time.monotonic() - start


@contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM stops the command like Ctrl-C (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(_signum: int, _frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@app.command("trajectory")
def trajectory(
    move: Annotated[
        list[str],
        typer.Option("--move", "-m", help="joint=position [rad or m] (repeatable)."),
    ],
    seconds: Annotated[
        float, typer.Option("--seconds", min=0.01, help="Time to reach the goal.")
    ] = 2.0,
    relative: Annotated[
        bool, typer.Option("--relative", help="Move the joints by the values, not to them.")
    ] = False,
    cubic: Annotated[
        bool, typer.Option("--cubic", help="Start and stop smoothly (zero end velocities).")
    ] = False,
    timeout: Annotated[
        float, typer.Option("--timeout", min=0.1, help="Seconds to wait for the graph.")
    ] = 10.0,
    domain_id: DomainId = None,
    namespace: Namespace = "",
) -> None:
    """Send one joint trajectory on ``/openral/joint_trajectory`` (from where the joints are
    to the goals in SECONDS), follow it and print how closely the joints tracked it."""
    require_ros()
    from openral_bridge.topics import JOINT_TRAJECTORY
    from openral_nodes.graph_names import namespaced_node
    from openral_nodes.runtime import Spinner, ros_session
    from openral_nodes.trajectory_sender import TrajectorySender, parse_moves

    moves = parse_moves(move)
    with ros_session(domain_id) as context:
        node = namespaced_node(
            "openral_trajectory_sender",
            checked(namespace),
            context=context,
            start_parameter_services=False,
        )
        try:
            with Spinner(context) as spinner, _sigterm_as_interrupt():
                spinner.add_node(node)
                sender = TrajectorySender(node)
                with progress() as bar:
                    task = bar.add_task(f"{JOINT_TRAJECTORY} ({seconds:g} s)", total=1.0)

                    def advance(done: float) -> None:
                        bar.update(task, completed=done)

                    report = sender.send(
                        moves,
                        seconds,
                        relative=relative,
                        cubic=cubic,
                        timeout_s=timeout,
                        on_progress=advance,
                    )
        finally:
            node.destroy_node()
    _print_report(report, seconds, cubic)


def _print_report(report: TrajectoryReport, seconds: float, cubic: bool) -> None:
    """The joints' start, goal, end and tracking error as a table, and one summary line."""
    from rich.table import Table

    table = Table(title=f"{'cubic' if cubic else 'linear'} trajectory, {seconds:g} s")
    for column in ("joint", "start", "goal", "reached", "max tracking error"):
        table.add_column(column, justify="left" if column == "joint" else "right")
    rows = zip(report.start, report.goal, report.reached, report.max_error, strict=True)
    for name, (start, goal, reached, error) in zip(report.names, rows, strict=True):
        table.add_row(name, f"{start:+.4f}", f"{goal:+.4f}", f"{reached:+.4f}", f"{error:.4f}")
    out.print(table)
    worst = max(report.max_error, default=0.0)
    out.print(
        f"followed {report.samples} desired points; joints within {worst:.4f} (rad or m) of "
        "the path at every one"
    )
