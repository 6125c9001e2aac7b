"""Every ``--help`` of the CLI reads as plain, reflowed text with click-style hints."""

from __future__ import annotations

import re
from typing import Annotated

import pytest
import typer
from openral_cli.help_text import command_group
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


PLACEHOLDER = re.compile(r"\S*<[^<>\s]+>\S*")
"""A word holding an angle-bracket placeholder: ``robots/<id>/robot.yaml;``."""


def _source_help(path: list[str]) -> str:
    """The help strings the command at ``path`` was written with (before rendering)."""
    command = typer.main.get_command(app)
    for name in path:
        command = command.commands[name]  # type: ignore[attr-defined]
    texts = [(command.help or "").partition("\f")[0]]
    for param in command.params:
        texts.append(getattr(param, "help", None) or "")
        shown = getattr(param, "show_default", None)
        texts.append(shown if isinstance(shown, str) else "")
    return "\n".join(texts)


def _help(path: list[str]) -> str:
    result = runner.invoke(app, [*path, "--help"], env={"COLUMNS": "250"})
    assert result.exit_code == 0, result.output
    return result.output


@pytest.mark.parametrize("path", PATHS, ids=lambda p: " ".join(p) or "openral")
def test_help_keeps_every_angle_bracket_placeholder(path: list[str]) -> None:
    text = _help(path)
    for word in PLACEHOLDER.findall(_source_help(path)):
        assert word.rstrip(".,;:") in text, f"{word!r} lost from:\n{text}"
    assert "//" not in text and ":/." not in text, f"a placeholder was dropped:\n{text}"


@pytest.mark.parametrize(
    ("path", "expected"),
    [([], "robots/<id>/robot.yaml"), (["robot", "scaffold"], "pkg:<dist>/<path>.xml")],
)
def test_the_reported_placeholders_print_as_written(path: list[str], expected: str) -> None:
    assert expected in _help(path)


def test_any_command_help_prints_tags_as_text() -> None:
    demo = command_group("Reads `<code>` and <b>tags</b> verbatim.")

    @demo.command()
    def show(
        where: Annotated[str, typer.Option(help="A path like robots/<id>/<file>.yaml.")] = "x",
    ) -> None:
        """Lists <slot> names."""

    @demo.command()
    def other() -> None:
        """Another command, so the group lists its commands."""

    group_help = runner.invoke(demo, ["--help"], env={"COLUMNS": "250"}).output
    assert "Reads <code> and <b>tags</b> verbatim." in group_help
    assert "Lists <slot> names." in group_help
    show_help = runner.invoke(demo, ["show", "--help"], env={"COLUMNS": "250"}).output
    assert "robots/<id>/<file>.yaml." in show_help and "Lists <slot> names." in show_help
