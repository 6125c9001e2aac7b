"""``openral ros view BAG``: a recorded rosbag2 bag in the browser view.

What is drawn is :mod:`openral_nodes.bag_view`'s (the frame tree, joints, camera images);
the view stays up until Ctrl-C. Needs rosbags (the ``ros`` extra) and rerun-sdk (the
``view`` extra), no running ROS graph.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from openral_core.errors import OpenralError

from openral_cli.browser_view import DEFAULT_VIEW_PORT, ViewPort, serve_bag_view
from openral_cli.commands.ros import app


@app.command("view")
def view(
    bag: Annotated[Path, typer.Argument(help="A rosbag2 bag folder (openral ros record's).")],
    view_port: ViewPort = DEFAULT_VIEW_PORT,
) -> None:
    """Show BAG in the browser view: its /tf frame tree as axes, its joint states as plots
    and its camera images, on the time line of their stamps; serve until Ctrl-C.

    Example:

        openral ros view out/run1
    """
    if not (bag / "metadata.yaml").is_file():
        raise OpenralError(f"{bag}: no metadata.yaml; expected a rosbag2 bag folder")
    serve_bag_view(bag, view_port)
