"""``--view`` and ``--view-port`` of ``sim run``, ``sim replay`` and ``deploy sim``: one
definition of the options, opening the view on a HAL, and serving it after a run ends.

The page (Rerun's web viewer, from the wheel) is ``http://127.0.0.1:PORT/`` and the data
stream ``127.0.0.1:PORT + 1``; both listen on 127.0.0.1 only and stop when the view closes
(:mod:`openral_sim.browser_view`).
"""

from __future__ import annotations

import signal
import threading
from typing import TYPE_CHECKING, Annotated

import typer
from openral_core.errors import OpenralError

from openral_cli.console import out

if TYPE_CHECKING:
    from pathlib import Path

    from openral_hal.protocol import RobotHal
    from openral_hal.view_feed import ViewFeed
    from openral_sim.browser_view import BrowserView

View = Annotated[
    bool,
    typer.Option(
        "--view",
        help="Serve a browser view of the run (Rerun's web viewer) on 127.0.0.1:--view-port.",
    ),
]
ViewPort = Annotated[
    int,
    typer.Option(
        "--view-port",
        min=1024,
        max=65534,
        help="Port of the view's page; its data stream uses the next port.",
    ),
]
DEFAULT_VIEW_PORT = 9090
"""The page's port (Rerun's own default); the data stream takes the next one."""


def open_view(hal: RobotHal, title: str, port: int) -> ViewFeed:
    """A feed drawing ``hal``'s scene in a new browser view; prints where to open it.

    Raises:
        OpenralError: The HAL has no MuJoCo model, rerun-sdk is missing, or a port is taken.
    """
    from openral_hal.protocol import MujocoBacked
    from openral_hal.view_feed import ViewFeed
    from openral_sim.sensor_sources import CameraSource

    try:
        from openral_sim.browser_view import BrowserView, ViewPorts, ViewUnavailable
    except ImportError:
        raise OpenralError("--view needs rerun-sdk: pip install 'openral[view]'") from None
    handles = hal.mujoco_handles() if isinstance(hal, MujocoBacked) else None
    if handles is None:
        raise OpenralError("--view: this scene has no MuJoCo model to draw")
    cameras = tuple(hal.camera_sensors()) if isinstance(hal, CameraSource) else ()
    ports = ViewPorts(web=port)
    try:
        view = BrowserView(handles[0], title=title, cameras=cameras, ports=ports)
    except ViewUnavailable as error:
        raise OpenralError(f"--view: {error}") from None
    out.print(f"view: {ports.url}", markup=False, soft_wrap=True)
    return ViewFeed(view, hal)


def serve_until_interrupted(feed: ViewFeed) -> None:
    """Keep the finished run's view up until Ctrl-C (or SIGTERM), then close it."""
    wait_for_stop(feed.view)


def wait_for_stop(view: BrowserView) -> None:
    """Serve ``view`` until Ctrl-C (or SIGTERM), then close it."""
    stop = threading.Event()
    handlers = {
        sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGINT, signal.SIGTERM)
    }
    out.print(f"serving the view at {view.ports.url} until Ctrl-C", markup=False, soft_wrap=True)
    try:
        stop.wait()
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
        view.close()


def serve_bag_view(bag: Path, port: int) -> None:
    """Draw a recorded bag in a new browser view and serve it until Ctrl-C.

    Raises:
        OpenralError: rerun-sdk or rosbags missing, a port taken, or a bag rosbags cannot
            read.
    """
    try:
        from openral_nodes.bag_view import show, survey
        from openral_sim.browser_view import BrowserView, ViewPorts, ViewUnavailable
    except ImportError as error:
        raise OpenralError(
            f"ros view needs rerun-sdk and rosbags ({error.name} is missing)"
        ) from None
    from rosbags.rosbag2 import ReaderError

    try:
        contents = survey(bag)
        ports = ViewPorts(web=port)
        view = BrowserView(
            None,
            title=str(bag),
            cameras=tuple(dict.fromkeys(contents.cameras.values())),
            ports=ports,
        )
        out.print(f"view: {ports.url}", markup=False, soft_wrap=True)
        show(bag, view, contents)
    except ViewUnavailable as error:
        raise OpenralError(f"--view-port: {error}") from None
    except ReaderError as error:
        reason = " ".join(str(error).split())  # rosbags quotes multi-line YAML errors
        raise OpenralError(f"{bag}: not a readable bag ({reason})") from None
    left = ", ".join(f"{topic} ({count})" for topic, count in sorted(contents.skipped.items()))
    out.print(
        f"drew {contents.frames} transforms, {contents.joint_states} joint states and "
        f"{contents.images} images" + (f"; left out {left}" if left else ""),
        markup=False,
        soft_wrap=True,
    )
    wait_for_stop(view)
