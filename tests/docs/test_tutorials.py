"""Every command of every tutorial runs, in page order, in a fresh copy of the repository.

The conventions a tutorial follows are in ``tests/docs/tutorial_runner.py``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tests.conftest import REPO
from tests.docs.tutorial_runner import (
    Command,
    FileWrite,
    TutorialRun,
    copy_repository,
    found,
    parse_tutorial,
    sandbox_environment,
)

TUTORIALS = sorted((REPO / "docs" / "tutorials").glob("*.md"))
VENV_BIN = REPO / ".venv" / "bin"


def _just_dir() -> Path:
    for candidate in (REPO / ".tools" / "venv" / "bin" / "just", shutil.which("just")):
        if candidate and Path(candidate).is_file():
            return Path(candidate).parent
    raise AssertionError("`just` is not installed; run ./bootstrap (it installs it in .tools/)")


@pytest.fixture(scope="module")
def ros_domain() -> str:
    """A ROS domain id no other openral process uses, so tutorial graphs stay private."""
    from openral_nodes.runtime import claim_domain_id

    return str(claim_domain_id())


def test_parser_reads_commands_output_exit_status_background_and_files() -> None:
    page = "\n".join(
        [
            "```console",
            "$ openral robot check x  # exit status 1",
            "│ x │ … │ 7 │",
            "$ openral deploy sim --config s.yaml &",
            "running…",
            "$ echo a \\",
            "  b",
            "```",
            '```yaml title="robots/x/robot.yaml"',
            "name: x",
            "```",
            "```yaml",
            "shown: only",
            "```",
        ]
    )
    steps = parse_tutorial(page, "t.md")
    assert steps == [
        Command("openral robot check x", "t.md:2", ["│ x │ … │ 7 │"], exit_status=1),
        Command("openral deploy sim --config s.yaml", "t.md:4", ["running…"], background=True),
        Command("echo a b", "t.md:6"),
        FileWrite("robots/x/robot.yaml", "name: x\n", "t.md:9"),
    ]


def test_output_lines_match_loosely_with_ellipsis_wildcards() -> None:
    output = "│ kuka_iiwa14  │      7 │ front, wrist │\nwrote /tmp/a/robots/x.yaml; ok"
    assert found("│ kuka_iiwa14 │ 7 │ front, wrist │", output)
    assert found("wrote …/robots/x.yaml…", output)
    assert not found("│ kuka_iiwa14 │ 8 │", output)


def test_run_fails_on_missing_output_and_on_unexpected_exit_status(tmp_path: Path) -> None:
    env = {**os.environ}
    run = TutorialRun(tmp_path, tmp_path, env)
    with pytest.raises(AssertionError, match="lacks \\['goodbye'\\]"):
        run.run(parse_tutorial("```console\n$ echo hello\ngoodbye\n```\n", "t.md"))
    with pytest.raises(AssertionError, match="exited 3, expected 0"):
        run.run(parse_tutorial("```console\n$ exit 3\n```\n", "t.md"))
    run.run(parse_tutorial("```console\n$ exit 3  # exit status 3\n```\n", "t.md"))


def test_run_waits_for_background_output_and_stops_jobs(tmp_path: Path) -> None:
    page = "\n".join(
        [
            "```console",
            "$ echo ready; sleep 30 &",
            "ready",
            "$ kill -INT %1",
            "```",
        ]
    )
    run = TutorialRun(tmp_path, tmp_path, {**os.environ})
    run.run(parse_tutorial(page, "t.md"))
    assert run.jobs[0].process.returncode is not None


def test_every_tutorial_has_commands() -> None:
    assert len(TUTORIALS) >= 4
    for tutorial in TUTORIALS:
        steps = parse_tutorial(tutorial.read_text(), tutorial.name)
        assert any(isinstance(s, Command) for s in steps), f"{tutorial.name} runs nothing"


@pytest.mark.parametrize("tutorial", TUTORIALS, ids=lambda p: p.stem)
def test_tutorial_commands_run(tutorial: Path, tmp_path: Path, ros_domain: str) -> None:
    sandbox = copy_repository(REPO, tmp_path / "repo")
    logs = tmp_path / "logs"
    logs.mkdir()
    env = sandbox_environment(sandbox, VENV_BIN, [_just_dir()])
    env["ROS_DOMAIN_ID"] = ros_domain
    steps = parse_tutorial(tutorial.read_text(), f"docs/tutorials/{tutorial.name}")
    TutorialRun(sandbox, logs, env).run(steps)
