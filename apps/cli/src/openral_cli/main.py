"""The ``openral`` command: builds the typer app and maps errors to exit codes.

Every command lives in ``openral_cli.commands.<noun>``; this module only assembles them.
An :class:`~openral_core.OpenralError` becomes one message on stderr and exit code 1;
usage errors exit 2 (typer's convention).
"""

from __future__ import annotations

import os
import sys

if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    # Headless: render offscreen with EGL. MuJoCo reads this once, when it is first
    # imported, so it is set before any command module is.
    os.environ.setdefault("MUJOCO_GL", "egl")

import typer
from openral_core.errors import OpenralError
from rich.console import Console
from rich.markup import escape

from openral_cli.commands import deploy, robot, ros, rskill, sim

app = typer.Typer(
    name="openral",
    help="Describe a robot once in robots/<id>/robot.yaml; simulate and deploy it.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)
app.add_typer(robot.app, name="robot")
app.add_typer(sim.app, name="sim")
app.add_typer(deploy.app, name="deploy")
app.add_typer(ros.app, name="ros")
app.add_typer(rskill.app, name="rskill")


def run() -> None:
    """Console-script entry point."""
    try:
        app()
    except OpenralError as error:
        message = escape(str(error))  # a message may contain [brackets]: not rich markup
        Console(stderr=True).print(
            f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True
        )
        sys.exit(1)


if __name__ == "__main__":
    run()
