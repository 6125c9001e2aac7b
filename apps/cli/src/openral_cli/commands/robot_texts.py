"""`openral robot urdf` and `openral robot srdf`: the robot's descriptions as the ROS graph
publishes them (/robot_description, /robot_description_semantic)."""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from openral_core.errors import one_line
from openral_core.loaded import LoadedRobot

from openral_cli.commands.robot_files import manifest_file as _manifest_file
from openral_cli.console import err
from openral_cli.console import error as print_error


class MeshUri(StrEnum):
    """How ``robot urdf`` names mesh files."""

    file = "file"
    relative = "relative"


def urdf(
    target: Annotated[str, typer.Argument(help="Robot id, manifest file or robot folder.")],
    out_file: Annotated[
        Path | None,
        typer.Option("--out", help="File to write the URDF to.", show_default="standard output"),
    ] = None,
    mesh_uri: Annotated[
        MeshUri,
        typer.Option(
            "--mesh-uri",
            help="file: meshes named by file URI in the model cache (rviz2, ROS tools); "
            "relative: written to meshes/ beside --out and named by relative path (MuJoCo's "
            "URDF compiler reads that form).",
        ),
    ] = MeshUri.file,
) -> None:
    """The robot's URDF, as the ROS graph publishes it on /robot_description.

    Mesh files (STL) are written once to the model cache and named by file URI, or with
    --mesh-uri relative beside the --out file. Exits 1 when the robot does not load or its
    model has no URDF form.
    """
    from openral_sim.robot_description import robot_description

    if mesh_uri is MeshUri.relative and out_file is None:
        raise typer.BadParameter("--mesh-uri relative names meshes beside --out FILE; give it")
    beside = out_file.resolve().parent if mesh_uri is MeshUri.relative and out_file else None
    name, text = _text_of(target, lambda robot: robot_description(robot, beside), "URDF")
    if out_file is None:
        typer.echo(text, nl=False)
        return
    try:
        out_file.write_text(text, encoding="utf-8")
    except OSError as problem:
        print_error(f"cannot write {out_file}: {problem.strerror or problem}")
        raise typer.Exit(1) from None
    err.print(f"wrote the URDF of {name} to {out_file}", highlight=True)


def srdf(
    target: Annotated[str, typer.Argument(help="Robot id, manifest file or robot folder.")],
) -> None:
    """The robot's SRDF (MoveIt's semantic description), as the ROS graph publishes it on
    /robot_description_semantic: arm and gripper groups, the end effector, named states and
    the collision pairs a planner need not check.

    Exits 1 when the robot does not load or its model has no URDF form.
    """
    from openral_sim.robot_description import robot_semantic_description

    _, text = _text_of(target, robot_semantic_description, "SRDF")
    typer.echo(text, nl=False)


def _text_of(target: str, make: Callable[[LoadedRobot], str], what: str) -> tuple[str, str]:
    """The robot's name and ``make(robot)``; exit 1 with one line when it has no tree."""
    from openral_core import open_robot
    from openral_core.registry import MANIFEST_NAME
    from openral_mujoco.errors import TreeUnsupported

    file = _manifest_file(target)
    robot = open_robot(file, check_folder_name=file.name == MANIFEST_NAME)
    try:
        return robot.name, make(robot)
    except TreeUnsupported as problem:
        print_error(f"robot {robot.name!r} has no {what}: {one_line(str(problem))}")
        raise typer.Exit(1) from None
