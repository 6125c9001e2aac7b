"""The ``openral`` command: builds the typer app and maps errors to exit codes.

Every command lives in ``openral_cli.commands.<noun>``; this module only assembles them.
An :class:`~openral_core.OpenralError` becomes one message on stderr and exit code 1;
usage errors exit 2 (typer's convention). All printing goes through
:mod:`openral_cli.console`, which never reads data as rich markup.
"""

from __future__ import annotations

import sys

import typer
from openral_core.errors import OpenralError
from openral_mujoco.display import render_offscreen_when_headless

from openral_cli.console import error as print_error
from openral_cli.help_text import command_group  # noqa: F401  (installs the help hints)
from openral_cli.optional_values import with_optional_values

render_offscreen_when_headless()  # before any command module imports mujoco

from openral_cli.commands import (  # noqa: E402, F401
    deploy,
    robot,
    ros,
    ros_graph,
    ros_record,
    ros_view,
    rskill,
    sim,
)

app = typer.Typer(
    name="openral",
    help="Describe a robot once in robots/<id>/robot.yaml; simulate and deploy it.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode="markdown",
)
app.add_typer(robot.app, name="robot")
app.add_typer(sim.app, name="sim")
app.add_typer(deploy.app, name="deploy")
app.add_typer(ros.app, name="ros")
app.add_typer(rskill.app, name="rskill")


def run() -> None:
    """Console-script entry point."""
    try:
        app(args=with_optional_values(sys.argv[1:]))
    except OpenralError as error:
        print_error(str(error))  # verbatim: a message may contain [brackets]
        sys.exit(1)


if __name__ == "__main__":
    run()
