"""Every command of every tutorial runs, in page order, in a fresh copy of the repository.

The conventions a tutorial follows are in ``tests/docs/tutorial_runner.py``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tests.conftest import REPO
from tests.docs.tutorial_output import ELISION, line_matches, match_all, match_prefix
from tests.docs.tutorial_runner import (
    Command,
    FileWrite,
    TutorialRun,
    copy_repository,
    created_paths,
    export_generated,
    parse_tutorial,
    remove_created,
    sandbox_environment,
)

TUTORIALS = sorted((REPO / "docs" / "tutorials").glob("*.md"))
REAL_TIME = {"mobile-sensing", "real-so101"}
"""Tutorials whose printed output is real-time behaviour (the base drives 0.75 m on two
seconds of wall-clock commands; an emulated servo bus answers within milliseconds): they
run alone, after the others (``exclusive``)."""
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


def test_a_shown_line_matches_loosely_within_itself() -> None:
    shown = "│ kuka_iiwa14 │ 7 │ front, wrist │"
    assert line_matches(shown, "│ kuka_iiwa14  │      7 │ front, wrist │")
    assert line_matches("wrote …/robots/x.yaml…", "wrote /tmp/a/robots/x.yaml; ok")
    assert line_matches("┏━┳━┓", "┏━━━━━┳━━━┓")
    assert not line_matches("│ kuka_iiwa14 │ 8 │", "│ kuka_iiwa14 │ 8 │ extra │")
    assert not line_matches("wrote x", "so we wrote x")


def test_output_is_shown_in_full_unless_an_elision_line_marks_the_cut() -> None:
    printed = ["a", "b", "c", "d"]
    assert match_all(["a", "b", "c", "d"], printed)
    assert not match_all(["a", "b", "d"], printed), "a silently dropped line"
    assert not match_all(["a", "b", "c"], printed), "a silently dropped tail"
    assert not match_all(["b", "c", "d"], printed), "a silently dropped head"
    assert match_all(["a", ELISION, "d"], printed)
    assert match_all([ELISION, "c", "d"], printed)
    assert match_all(["a", "b", ELISION, "c", "d"], printed), "an elision may cover nothing"
    assert not match_all(["a", ELISION, "b", "a"], printed), "order still counts"
    assert match_prefix(["a", "b"], printed) == 2
    assert match_prefix(["a", ELISION, "c"], printed) == 3
    assert match_prefix(["b"], printed) is None


def test_a_tutorial_runs_without_the_results_a_reader_committed(tmp_path: Path) -> None:
    page = "\n".join(
        [
            "```console",
            "$ openral robot scaffold --mjcf pkg:x/y.xml --name my_arm",
            "```",
            '```yaml title="robots/franka_panda/scenes/mine.yaml"',
            "a: 1",
            "```",
        ]
    )
    steps = parse_tutorial(page, "t.md")
    assert created_paths(steps) == ["robots/franka_panda/scenes/mine.yaml", "robots/my_arm"]
    (tmp_path / "robots" / "franka_panda" / "scenes").mkdir(parents=True)
    (tmp_path / "robots" / "franka_panda" / "scenes" / "mine.yaml").write_text("a: 0\n")
    (tmp_path / "robots" / "franka_panda" / "scenes" / "tabletop.yaml").write_text("b: 0\n")
    assert remove_created(tmp_path, steps) == ["robots/franka_panda/scenes/mine.yaml"]
    assert sorted(p.name for p in (tmp_path / "robots" / "franka_panda" / "scenes").iterdir()) == [
        "tabletop.yaml"
    ]


def test_run_fails_on_missing_output_and_on_unexpected_exit_status(tmp_path: Path) -> None:
    env = {**os.environ}
    run = TutorialRun(tmp_path, tmp_path, env)
    with pytest.raises(AssertionError, match="'goodbye' differs from printed line 1 'hello'"):
        run.run(parse_tutorial("```console\n$ echo hello\ngoodbye\n```\n", "t.md"))
    with pytest.raises(AssertionError, match="printed line 2 'two' is not shown"):
        run.run(parse_tutorial("```console\n$ printf 'one\\ntwo\\n'\none\n```\n", "t.md"))
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


@pytest.mark.parametrize(
    "tutorial",
    [
        pytest.param(t, id=t.stem, marks=[pytest.mark.exclusive] if t.stem in REAL_TIME else [])
        for t in TUTORIALS
    ],
)
def test_tutorial_commands_run(tutorial: Path, tmp_path: Path, ros_domain: str) -> None:
    sandbox = copy_repository(REPO, tmp_path / "repo")
    logs = tmp_path / "logs"
    logs.mkdir()
    env = sandbox_environment(sandbox, VENV_BIN, [_just_dir()])
    env["ROS_DOMAIN_ID"] = ros_domain
    steps = parse_tutorial(tutorial.read_text(), f"docs/tutorials/{tutorial.name}")
    if any(path.startswith("robots/") for path in remove_created(sandbox, steps)):
        export_generated(sandbox, env)
    TutorialRun(sandbox, logs, env).run(steps)
