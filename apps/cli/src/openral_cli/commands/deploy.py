"""``openral deploy``: run a robot as a live ROS 2 graph, simulated or real.

Example::

    openral deploy sim --config robots/franka_panda/scenes/tabletop.yaml --no-viewer
    openral deploy real --robot so101 --transport /dev/ttyACM0 --arm-id my_follower

The scene's robot comes up as one :class:`~openral_nodes.manifest_node.ManifestLifecycleNode`
in this process, driven through configure and activate here (there is no ``ros2 launch``).
The node reads the scene file and the robot's manifest once, at configure; a problem in
either ends the command with one line.
It runs until Ctrl-C or SIGTERM (or ``--duration``), then deactivates, cleans up and
exits 0; a ``shutdown`` transition requested over ROS ends it with exit 0 too. ``deploy
real`` runs the same node on the robot's real driver (``real`` in its manifest): the arm
is held where it is at bring-up, and at the end it holds, then takes the manifest's
``shutdown`` torque state.
``openral ros topics`` in a second terminal lists what it publishes.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from openral_core.errors import OpenralError

from openral_cli.browser_view import DEFAULT_VIEW_PORT, View, ViewPort
from openral_cli.commands.recording import start_recording, stop_recording
from openral_cli.console import out
from openral_cli.deploy_interfaces import print_interfaces
from openral_cli.help_text import command_group
from openral_cli.namespace_option import Namespace, bad_namespace
from openral_cli.ros_available import require_ros

if TYPE_CHECKING:
    from openral_nodes.manifest_node import ManifestLifecycleNode
    from rclpy.context import Context

app = command_group("Run robots as ROS 2 graphs.")
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
CameraRate = Annotated[
    float | None,
    typer.Option(
        "--camera-rate",
        min=0.1,
        max=1000.0,
        help="Publish every camera, depth camera and lidar at this rate [Hz], at most the "
        "control rate (default: each sensor's rate_hz).",
    ),
]
NoTf = Annotated[
    bool,
    typer.Option(
        "--no-tf",
        help="Publish no /tf or /tf_static (another node, e.g. robot_state_publisher, does).",
    ),
]
NoStaticTf = Annotated[
    bool,
    typer.Option(
        "--no-static-tf",
        help="With --no-tf, also leave out the frames no URDF holds (world, odom, scene cameras).",
    ),
]
Duration = Annotated[
    float | None,
    typer.Option(
        "--duration", min=0.0, help="Stop after this many seconds (default: run until Ctrl-C)."
    ),
]
DomainId = Annotated[
    int | None,
    typer.Option("--domain-id", min=0, max=232, help="ROS domain id (default: ROS_DOMAIN_ID)."),
]
Record = Annotated[
    Path | None,
    typer.Option(
        "--record",
        help="Record every topic into a rosbag2 bag (MCAP) in this new folder.",
        show_default=False,
    ),
]
Overwrite = Annotated[
    bool, typer.Option("--overwrite", help="Replace --record's folder if it holds a bag.")
]


@app.command("sim")
def sim(
    config: Annotated[Path, typer.Option("--config", help="Deploy-scene YAML file.")],
    no_viewer: Annotated[
        bool, typer.Option("--no-viewer", help="Never open the MuJoCo viewer.")
    ] = False,
    camera_rate: CameraRate = None,
    manifest: Annotated[
        Path | None, typer.Option("--manifest", help="Manifest file (default: the scene's robot).")
    ] = None,
    joint_state_rate: Annotated[
        float,
        typer.Option(
            "--joint-state-rate",
            min=0.1,
            max=1000.0,
            help="/joint_states, /tf, /odom rate [Hz]; at or above the scene's state_rate_hz "
            "every new state goes out once.",
        ),
    ] = 100.0,
    no_tf: NoTf = False,
    no_static_tf: NoStaticTf = False,
    namespace: Namespace = "",
    duration: Duration = None,
    domain_id: DomainId = None,
    record: Record = None,
    overwrite: Overwrite = False,
    view: View = False,
    view_port: ViewPort = DEFAULT_VIEW_PORT,
    loop_priority: Annotated[
        int,
        typer.Option(
            "--loop-priority",
            min=0,
            max=99,
            help="Run the control loop's thread at this real-time priority (1-99, as a "
            "ros2_control driver's thread_priority; needs root or CAP_SYS_NICE), e.g. standing "
            "in for an arm's driver beside deploy real. 0: ordinary scheduling.",
        ),
    ] = 0,
) -> None:
    """Bring SCENE's robot up as a ROS 2 graph: joint states, cameras, actions, E-stop."""
    parameters = _node_parameters(config, manifest, not no_viewer, camera_rate, joint_state_rate)
    parameters.update(_tf_parameters(no_tf, no_static_tf))
    parameters["loop_priority"] = loop_priority
    parameters["view_port"] = view_port if view else 0
    require_ros()
    from openral_nodes.runtime import ros_session

    with ros_session(domain_id=domain_id) as context:
        domain = context.get_domain_id()
        recorder = None if record is None else start_recording(record, overwrite, domain)
        try:
            title = f"deploy sim: {{robot}} in {config.name}"
            reason, elapsed_s = _run_graph(context, parameters, title, duration, namespace)
        finally:
            if recorder is not None:
                stop_recording(recorder)
    stopped = f"stopped ({reason}) after {elapsed_s:.1f} s; clean shutdown"
    out.print(stopped, soft_wrap=False, highlight=True)


Twin = Annotated[
    Path | None,
    typer.Option(
        "--twin",
        help="SCENE: pose the real robot in this scene (its cameras, TF, view); commands "
        "into its fixed geometry are refused.",
    ),
]


@app.command("real")
def real(
    transport: Annotated[
        str, typer.Option("--transport", help="The robot's bus (/dev/ttyACM0, /dev/pts/N).")
    ],
    robot: Annotated[
        str | None, typer.Option("--robot", help="Robot id with a real section (so101).")
    ] = None,
    manifest: Annotated[
        Path | None, typer.Option("--manifest", help="Manifest file instead of --robot.")
    ] = None,
    arm_id: Annotated[
        str | None,
        typer.Option("--arm-id", help="Which arm's calibration (LeRobot's --robot.id)."),
    ] = None,
    calibration: Annotated[
        Path | None, typer.Option("--calibration", help="The calibration file to use.")
    ] = None,
    camera: Annotated[
        list[str] | None,
        typer.Option(
            "--camera",
            help="NAME=DEVICE: an RGB sensor's camera (0, /dev/video0, file:clip.mp4).",
        ),
    ] = None,
    twin: Twin = None,
    no_tf: NoTf = False,
    no_static_tf: NoStaticTf = False,
    namespace: Namespace = "",
    duration: Duration = None,
    domain_id: DomainId = None,
    record: Record = None,
    overwrite: Overwrite = False,
) -> None:
    """Bring ROBOT's real arm up on TRANSPORT as the same ROS 2 graph as deploy sim."""
    if (robot is None) == (manifest is None):
        raise typer.BadParameter("give the robot: --robot ID or --manifest FILE (one of them)")
    parameters = _real_parameters(robot, manifest, transport, arm_id, calibration, camera)
    parameters.update(_tf_parameters(no_tf, no_static_tf), twin_scene=_twin_scene(twin))
    require_ros()
    from openral_hal.realtime import ahead_of_other_programs
    from openral_nodes.runtime import ros_session

    if domain_id is not None:  # a driver's own ROS link (ros2_control) joins the same domain
        os.environ["ROS_DOMAIN_ID"] = str(domain_id)
    with ros_session(domain_id=domain_id) as context:
        recorder = None
        if record is not None:
            recorder = start_recording(record, overwrite, context.get_domain_id())
        try:
            title = f"deploy real: {{robot}} on {transport}"  # {robot}: the node's, once loaded
            with ahead_of_other_programs():  # the recorder (started above) stays ordinary
                reason, elapsed_s = _run_graph(context, parameters, title, duration, namespace)
        finally:
            if recorder is not None:
                stop_recording(recorder)
    out.print(f"stopped ({reason}) after {elapsed_s:.1f} s; clean shutdown", soft_wrap=False)


def _real_parameters(
    robot: str | None,
    manifest: Path | None,
    transport: str,
    arm_id: str | None,
    calibration: Path | None,
    cameras: list[str] | None,
) -> dict[str, Any]:
    """The manifest node's parameters for ``deploy real`` (files checked first)."""
    if calibration is not None:
        _require_file(calibration, "calibration", "~/.cache/huggingface/lerobot/calibration/...")
    if manifest is not None:
        _require_file(manifest, "manifest", "robots/so101/robot.yaml")
    return {
        "robot_id": robot or "",
        "manifest_path": str(manifest.resolve()) if manifest is not None else "",
        "hal_mode": "real",
        "transport": transport,
        "viewer_enabled": False,
        "calibration_file": str(calibration.resolve()) if calibration else "",
        "arm_id": arm_id or "",
        "cameras": list(cameras or [""]),
    }


def _twin_scene(twin: Path | None) -> str:
    """The ``twin_scene`` parameter of ``--twin`` (the file checked first; "" for none)."""
    if twin is None:
        return ""
    _require_file(twin, "twin scene", "robots/franka_panda/scenes/tabletop.yaml")
    return str(twin.resolve())


def _tf_parameters(no_tf: bool, no_static_tf: bool) -> dict[str, Any]:
    """``publish_tf`` and ``publish_static_tf`` of ``--no-tf`` and ``--no-static-tf``."""
    if no_static_tf and not no_tf:
        raise typer.BadParameter("--no-static-tf goes with --no-tf (it narrows what --no-tf keeps)")
    return {"publish_tf": not no_tf, "publish_static_tf": not no_static_tf}


def _run_graph(
    context: Context,
    parameters: dict[str, Any],
    title: str,
    duration: float | None,
    namespace: str = "",
) -> tuple[str, float]:
    """Bring the node up, serve until a signal, ``duration`` or a shutdown transition, then
    take it down; why it stopped and how long it ran [s]."""
    from openral_nodes.runtime import spin_until
    from rclpy.executors import SingleThreadedExecutor

    stop = threading.Event()
    node = _make_node(context, parameters, stop, namespace)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in STOP_SIGNALS}
    started = time.monotonic()
    try:
        _transition(node, "configure")
        _transition(node, "activate")
        print_interfaces(node, title)
        spin_until(executor, stop, timeout_s=duration)
    finally:
        reason = _shut_down(node, stop)
        executor.shutdown()
        node.destroy_node()  # type: ignore[no-untyped-call]
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return reason, time.monotonic() - started


def _node_parameters(
    config: Path,
    manifest: Path | None,
    viewer: bool,
    camera_rate: float | None,
    joint_state_rate: float,
) -> dict[str, Any]:
    """The manifest node's parameters from the command line (files checked first)."""
    _require_file(config)
    parameters: dict[str, Any] = {
        "sim_env_yaml": str(config.resolve()),
        "hal_mode": "sim",
        "viewer_enabled": viewer,
        "camera_publish_rate_hz": float(camera_rate or 0.0),  # 0: each sensor's own rate
        "joint_state_rate_hz": float(joint_state_rate),
    }
    if manifest is not None:
        _require_file(manifest, "manifest", "robots/franka_panda/robot.yaml")
        parameters["manifest_path"] = str(manifest.resolve())
    return parameters


def _require_file(
    file: Path, what: str = "scene", example: str = "robots/franka_panda/scenes/tabletop.yaml"
) -> None:
    """A missing file is reported before any ROS work starts (the node reads it)."""
    if not file.is_file():
        raise OpenralError(f"{file}: no such {what} file; expected a YAML file such as {example}")


def _make_node(
    context: Context, parameters: dict[str, Any], stop: threading.Event, namespace: str = ""
) -> ManifestLifecycleNode:
    """The manifest node as deploy runs it: boot errors reported by the caller, ``stop``
    set by a shutdown transition (also one requested over ROS), in ``namespace``."""
    from openral_nodes.manifest_node import ManifestLifecycleNode

    try:
        node = ManifestLifecycleNode(
            context=context,
            namespace=namespace,
            parameter_overrides=parameters,
            log_boot_errors=False,
            shutdown_event=stop,
        )
    except Exception as error:  # rclpy's InvalidNamespaceException and kin
        raise bad_namespace(namespace, error) from None
    node.heap.enabled = True  # short garbage collections while active (heap_freeze)
    return node


def _transition(node: ManifestLifecycleNode, name: str) -> None:
    """Run one lifecycle transition; a failure becomes one clear error."""
    from rclpy.lifecycle import TransitionCallbackReturn

    result = getattr(node, f"trigger_{name}")()
    if result != TransitionCallbackReturn.SUCCESS:
        raise OpenralError(f"{name} failed: {node.boot_error or result}")


def _shut_down(node: ManifestLifecycleNode, stop: threading.Event) -> str:
    """Deactivate and clean up from whatever state the node reached.

    Returns:
        Why the graph stopped: a shutdown transition (the node is finalized), a signal
        (``stop`` is set) or the end of ``--duration``.
    """
    state = node.lifecycle_state
    if state == "finalized":
        return "shutdown transition requested over ROS"
    if state == "active":
        node.trigger_deactivate()  # type: ignore[no-untyped-call]
        state = "inactive"
    if state == "inactive":
        node.trigger_cleanup()  # type: ignore[no-untyped-call]
    return "signal" if stop.is_set() else "--duration"
