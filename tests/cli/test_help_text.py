"""Every ``--help`` of the CLI reads as plain, reflowed text with click-style hints."""

from __future__ import annotations

import re

import pytest
import typer
from openral_cli.main import app
from typer.testing import CliRunner

runner = CliRunner()


def _command_paths() -> list[list[str]]:
    root = typer.main.get_command(app)
    paths: list[list[str]] = []

    def walk(command: object, path: list[str]) -> None:
        paths.append(path)
        for name, sub in sorted(getattr(command, "commands", {}).items()):
            walk(sub, [*path, name])

    walk(root, [])
    return paths


PATHS = _command_paths()


def test_the_walk_reaches_every_command_group_and_leaf() -> None:
    names = {" ".join(path) for path in PATHS}
    assert {"robot check", "ros snapshot", "deploy sim", "sim run", "rskill run"} <= names


@pytest.mark.parametrize("path", PATHS, ids=lambda p: " ".join(p) or "openral")
def test_help_has_no_type_names_markup_leftovers_or_broken_lines(path: list[str]) -> None:
    result = runner.invoke(app, [*path, "--help"], env={"COLUMNS": "100"})
    assert result.exit_code == 0, result.output
    text = result.output
    assert "<bool>" not in text and "list[" not in text, text
    assert "``" not in text, text
    assert not re.search(r"(?<![\w$]){[a-z_]+}", text), f"an unfilled placeholder:\n{text}"
    # A flag shows no hint: the --help row is the option and its description only.
    help_row = next(line for line in text.splitlines() if "--help" in line)
    assert re.search(r"--help\s+Show this message", help_row), help_row
