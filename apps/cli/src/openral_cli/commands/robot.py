"""``openral robot``: list, show, validate, check, scaffold and export (URDF) the robots
under robots/.

Examples::

    openral robot list
    openral robot show franka_panda
    openral robot validate --all
    openral robot validate path/to/robot.yaml
    openral robot check --all
    openral robot scaffold --mjcf pkg:<distribution>/<path>.xml --name my_arm
    openral robot urdf franka_panda --out panda.urdf
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from openral_core.errors import ManifestError, OpenralError, one_line

from openral_cli.commands.robot_calibrate import calibrate
from openral_cli.commands.robot_files import manifest_file as _manifest_file
from openral_cli.commands.robot_texts import srdf, urdf
from openral_cli.console import err, highlighted, line, out, styled
from openral_cli.help_text import command_group

if TYPE_CHECKING:
    from openral_core import RobotDescription
    from rich.table import Table


app = command_group("Inspect and validate robot manifests.")
app.command("calibrate")(calibrate)
app.command("urdf")(urdf)
app.command("srdf")(srdf)


@app.command("list")
def list_robots() -> None:
    """Table of every robot: id, joints, grippers, cameras, floating base."""
    from openral_core import load_robot_by_id, robot_ids
    from rich.table import Table

    table = Table(title="robots/")
    table.add_column("id", no_wrap=True)
    for column in ("joints", "grippers"):
        table.add_column(column, no_wrap=True, justify="right")
    table.add_column("cameras")
    table.add_column("floating base", no_wrap=True)
    table.add_column("model", overflow="fold", min_width=20)
    invalid: list[ManifestError] = []
    for robot_id in robot_ids():
        try:
            robot = load_robot_by_id(robot_id)
        except ManifestError as error:
            invalid.append(error)
            table.add_row(styled(f"{robot_id} (invalid)", "red"), "-", "-", "-", "-", "-")
            continue
        sim = robot.sim
        cameras = [s.name for s in robot.sensors if s.kind == "rgb"]
        table.add_row(
            robot.name,
            str(len(robot.joints)),
            str(len(sim.grippers)) if sim else "-",
            ", ".join(cameras) or "-",
            ("yes" if sim.floating_base else "no") if sim else "-",
            _short_uri(sim.mjcf_uri) if sim else "-",
        )
    out.print(table)
    for problem in invalid:  # the first issue, where it is; validate lists them all
        more = len(problem.issues) - 1
        rest = f" (and {more} more: `openral robot validate {problem.file}`)" if more else ""
        err.print(line(("✗", "red"), f" {problem.issues[0].format()}{rest}"))
    if invalid:
        raise typer.Exit(1)


def _short_uri(uri: str) -> str:
    """``scheme:first/…/last`` so a long package path fits a table cell."""
    scheme, _, rest = uri.partition(":")
    parts = rest.split("/")
    if len(parts) <= 2:
        return uri
    return f"{scheme}:{parts[0]}/…/{parts[-1]}"


@app.command("show")
def show(robot_id: Annotated[str, typer.Argument(help="Robot id (folder under robots/).")]) -> None:
    """The resolved HAL wiring, VLA slot table and joint-name map of one robot."""
    from openral_core import load_robot_by_id, manifest_path, robot_tables
    from openral_core.models import LimitedJoint
    from rich.table import Table

    robot = load_robot_by_id(robot_id)
    tables = robot_tables(robot)
    header = line((robot.display_name, "bold"), f" ({robot.name}) — {manifest_path(robot_id)}")
    out.print(highlighted(header))
    wiring = tables.hal_wiring
    joints = Table(title="joints and HAL wiring")
    for column in ("joint", "type", "limits", "MJCF name", "qpos", "qvel", "actuator"):
        joints.add_column(column)
    for joint in robot.joints:
        limits = joint.position_limits if isinstance(joint, LimitedJoint) else None
        joints.add_row(
            joint.name,
            str(joint.type),
            f"[{limits[0]:g}, {limits[1]:g}]" if limits else "-",
            tables.joint_name_map[joint.name],
            str(wiring.joint_qpos_addr[joint.name]) if wiring else "-",
            str(wiring.joint_qvel_addr[joint.name]) if wiring else "-",
            str(wiring.actuator_index[joint.name]) if wiring else "-",
        )
    out.print(joints)
    if wiring:
        _print_sim_summary(wiring.mjcf_uri, robot)
    slots = Table(title="VLA camera slots")
    slots.add_column("sensor")
    slots.add_column("slot")
    for slot in tables.vla_slots:
        slots.add_row(slot.sensor, slot.slot)
    out.print(slots if tables.vla_slots else "no RGB cameras: no VLA slots")


def _print_sim_summary(mjcf_uri: str, robot: RobotDescription) -> None:
    from openral_core import robot_tables
    from rich.table import Table

    wiring = robot_tables(robot).hal_wiring
    assert wiring is not None
    out.print(
        f"model: {mjcf_uri}  floating base: {wiring.floating_base}  "
        f"keyframe: {wiring.keyframe_index}  seed ctrl from qpos: {wiring.seed_ctrl_from_qpos}  "
        f"control: {wiring.control_mode}  settle steps: {wiring.settle_steps_default}",
        highlight=True,
    )
    if not wiring.grippers:
        return
    grippers = Table(title="grippers")
    for column in (
        "joint",
        "actuator",
        "mirror",
        "ctrl range",
        "qpos addrs",
        "scale",
        "read",
        "write",
    ):
        grippers.add_column(column)
    for g in wiring.grippers:
        grippers.add_row(
            g.joint,
            str(g.actuator_index),
            "-" if g.mirror_actuator_index is None else str(g.mirror_actuator_index),
            f"[{g.ctrl_range[0]:g}, {g.ctrl_range[1]:g}]",
            ", ".join(map(str, g.qpos_addrs)),
            f"{g.qpos_scale:g}",
            g.read_mode,
            g.write_mode,
        )
    out.print(grippers)


@app.command("validate")
def validate(
    targets: Annotated[
        list[str] | None,
        typer.Argument(help="Robot ids, manifest files or robot folders.", show_default=False),
    ] = None,
    all_robots: Annotated[bool, typer.Option("--all", help="Validate every robot.")] = False,
) -> None:
    """Validate manifests; print every problem as file:line:col: field: message.

    Exits 1 when any file is invalid, 2 when nothing was named.
    """
    from openral_core import load_robot
    from openral_core.registry import MANIFEST_NAME

    files = _named_manifests(targets, all_robots, "validate")
    failures = 0
    for file in files:
        try:
            load_robot(file, check_folder_name=file.name == MANIFEST_NAME)
        except ManifestError as error:
            failures += 1
            err.print(line(f"{file}: ", ("INVALID", "red")))
            for issue in error.issues:
                err.print(f"  {issue.format()}")
            continue
        out.print(line(f"{file}: ", ("OK", "green")))
    if failures:
        err.print(f"{failures} of {len(files)} file(s) invalid", highlight=True)
        raise typer.Exit(1)


def _named_manifests(targets: list[str] | None, all_robots: bool, verb: str) -> list[Path]:
    """Manifest files named on the command line (plus every robot with --all); exit 2 if none."""
    from openral_core import manifest_path, robot_ids

    files = [_manifest_file(t) for t in targets or []]
    if all_robots:
        files += [manifest_path(robot_id) for robot_id in robot_ids()]
    if not files:
        err.print(f"name robot ids or files to {verb}, or pass --all", highlight=True)
        raise typer.Exit(2)
    return files


@app.command("check")
def check(
    targets: Annotated[
        list[str] | None,
        typer.Argument(help="Robot ids, manifest files or robot folders.", show_default=False),
    ] = None,
    all_robots: Annotated[bool, typer.Option("--all", help="Check every robot.")] = False,
    verbose: Annotated[
        bool, typer.Option("--verbose", "-v", help="Show passing checks too.")
    ] = False,
) -> None:
    """Load each robot's MJCF and verify the manifest's wiring against it.

    Checks joint names, qpos/qvel addresses, which joint each actuator drives, gripper
    control ranges, the keyframe, the floating base and sensor cameras/bodies/sites. Each
    row names the manifest's file:line:col of its field. Exits 1 on any mismatch or any
    robot that could not be checked, 2 when nothing was named.
    """
    from rich.table import Table

    files = _named_manifests(targets, all_robots, "check")
    summary = Table(title="robot check")
    for column in ("robot", "model", "checks", "failed"):
        summary.add_column(column)
    outcomes = [_check_one(file, verbose, summary) for file in files]
    out.print(summary)
    mismatched, unchecked = outcomes.count("mismatch"), outcomes.count("unchecked")
    if mismatched or unchecked:
        err.print(_check_verdict(mismatched, unchecked, len(files)), highlight=True)
        raise typer.Exit(1)


def _warn_deprecated(robot: RobotDescription) -> None:
    """One located warning per model URI in a deprecated scheme, with its replacement."""
    from openral_core.located import issue_at
    from openral_mujoco.mjcf_uri import deprecated_uris

    for field, uri, replacement in deprecated_uris(robot):
        message = f"{uri!r} is deprecated; write {replacement!r} (the same file)"
        err.print(line(("!", "yellow"), f" {issue_at(robot, field, message).format()}"))


def _check_one(file: Path, verbose: bool, summary: Table) -> str:
    """Check one manifest: print its table of rows (failed ones, all with ``verbose``) and
    add its summary row; ``"ok"``, ``"mismatch"`` or ``"unchecked"`` (it did not load)."""
    from openral_core import load_robot
    from openral_core.registry import MANIFEST_NAME
    from openral_mujoco.mjcf_uri import robot_model_file
    from openral_mujoco.model_check import check_robot, compile_robot_model, row_location
    from rich.table import Table

    try:
        robot = load_robot(file, check_folder_name=file.name == MANIFEST_NAME)
        path = robot_model_file(robot, file.parent)  # located error without a sim block
        model = compile_robot_model(robot, path)
    except OpenralError as error:  # each names its manifest file already
        issues = error.issues if isinstance(error, ManifestError) else ()
        for text in [issue.format() for issue in issues] or [one_line(str(error))]:
            err.print(line(("✗", "red"), f" {text}"))
        summary.add_row(file.parent.name, "-", "-", styled("could not be checked", "red"))
        return "unchecked"
    _warn_deprecated(robot)
    rows = check_robot(robot, model)
    failures = [row for row in rows if not row.ok]
    shown = rows if verbose else failures
    if shown:
        table = Table(title=f"{robot.name}: {file} against {path.name}")
        for column in ("at", "field", "manifest"):
            table.add_column(column, no_wrap=True)
        table.add_column("model")
        table.add_column("", no_wrap=True)
        for row in shown:
            at = row_location(robot, row)
            mark = styled("ok", "green") if row.ok else styled("MISMATCH", "red")
            table.add_row(
                f"{at.file.name}:{at.line}:{at.column}", row.field, row.expected, row.actual, mark
            )
        out.print(table)
    status = styled(str(len(failures)), "red" if failures else "green")
    summary.add_row(robot.name, path.name, str(len(rows)), status)
    return "mismatch" if failures else "ok"


def _check_verdict(mismatched: int, unchecked: int, total: int) -> str:
    """The last line of a failed ``robot check``: robots that do not match their model, and
    robots whose manifest or model did not load (never counted as mismatches)."""
    if not mismatched:
        return f"{unchecked} of {total} robot(s) could not be checked"
    verdict = f"{mismatched} of {total} robot(s) do not match their model"
    return f"{verdict}; {unchecked} could not be checked" if unchecked else verdict


@app.command("scaffold")
def scaffold(
    mjcf: Annotated[str, typer.Option("--mjcf", help="MJCF URI, e.g. pkg:<dist>/<path>.xml")],
    name: Annotated[str, typer.Option("--name", help="Robot id (folder under robots/).")],
    out_dir: Annotated[
        Path | None,
        typer.Option(
            "--out", help="Folder to write robot.yaml into.", show_default="robots/<name>"
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
    allow_outside: Annotated[
        bool,
        typer.Option(
            "--allow-outside",
            help="Accept a model (or files it loads) outside the robot folder or package; "
            "checking the draft later then needs OPENRAL_ALLOW_OUTSIDE=1.",
        ),
    ] = False,
) -> None:
    """Draft a robot.yaml from an MJCF model; lines marked `# REVIEW:` need a human."""
    from openral_core.paths import repo_root
    from openral_core.registry import MANIFEST_NAME
    from openral_hal.scaffold import scaffold_manifest

    folder = out_dir or repo_root() / "robots" / name
    target = folder / MANIFEST_NAME
    if target.exists() and not force:
        err.print(f"{target} exists; pass --force to overwrite it", highlight=True)
        raise typer.Exit(1)
    text = scaffold_manifest(mjcf, name, folder, allow_outside=allow_outside)
    folder.mkdir(parents=True, exist_ok=True)
    target.write_text(text, encoding="utf-8")
    typed = shlex.quote(str(target))  # the commands below paste into a shell as they are
    out.print(
        f"wrote {target}; review the lines marked REVIEW, then run "
        f"`openral robot validate {typed}` and `openral robot check {typed}`",
        highlight=True,
    )
