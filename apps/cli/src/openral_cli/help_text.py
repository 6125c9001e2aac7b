"""How the CLI's ``--help`` reads: reflowed Markdown paragraphs and plain type hints.

Every command group is made by :func:`command_group`, so help text is written once, as
Markdown in docstrings and ``help=`` strings (``code`` spans in backticks; a blank line
separates paragraphs, single line breaks are reflowed). Option and argument hints follow
click's convention: a flag shows none, a value its kind (``TEXT``, ``INTEGER``,
``FLOAT``, ``PATH``) or its choices, a repeated argument its element's kind; the usage
line names arguments in capitals (``TOPIC``, ``[VALUES]...``), not ``{topic}``. A
placeholder in angle brackets (``robots/<id>/robot.yaml``) prints as written: help is
rendered by :class:`~openral_cli.help_markdown.PlainAngleMarkdown`, which reads no HTML.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import typer
from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption

__all__ = ["PARAM_HELP", "command_group"]

PARAM_HELP = (
    "Policy parameter key=value (repeatable): a JSON value where it is JSON, "
    "key.field=value for one field of a nested config."
)
"""The help of every command's ``--param``/``-p`` (see :mod:`openral_eval.policy_config`)."""
_KINDS = {"str": "TEXT", "int": "INTEGER", "float": "FLOAT", "Path": "PATH", "bool": "BOOLEAN"}


def _hint(param: TyperArgument | TyperOption, ctx: object) -> str | None:
    if isinstance(param, TyperOption) and param.is_flag:
        return None
    shown = TyperOption.display_type(param, ctx).strip("<>")  # type: ignore[arg-type]
    if shown.startswith("list[") and shown.endswith("]"):
        shown = shown[5:-1]
    return "|".join(_KINDS.get(part, part.upper()) for part in shown.split("|"))


def _usage_name(param: TyperArgument) -> str:
    """``TOPIC`` for a required argument, ``[VALUES]...`` for an optional repeated one."""
    name = param.display_name_raw.upper()
    name = name if param.required else f"[{name}]"
    return name + ("..." if param.nargs != 1 else "")


def _angle_brackets_kept() -> None:
    """Render help with :class:`PlainAngleMarkdown` (imports rich: only when help prints)."""
    from typer import rich_utils

    from openral_cli.help_markdown import PlainAngleMarkdown

    rich_utils.Markdown = PlainAngleMarkdown  # type: ignore[attr-defined]


def _keeping_angle_brackets(format_help: Callable[..., None]) -> Callable[..., None]:
    def format_help_kept(self: Any, ctx: Any, formatter: Any) -> None:
        _angle_brackets_kept()
        format_help(self, ctx, formatter)

    return format_help_kept


def _install() -> None:
    TyperCommand.format_help = _keeping_angle_brackets(TyperCommand.format_help)  # type: ignore[method-assign]
    TyperGroup.format_help = _keeping_angle_brackets(TyperGroup.format_help)  # type: ignore[method-assign]
    TyperOption.display_type_rich = _hint  # type: ignore[assignment,method-assign]
    TyperArgument.display_type_rich = _hint  # type: ignore[assignment,method-assign]
    TyperArgument._usage_display_name = _usage_name  # type: ignore[assignment,method-assign]


def command_group(help_text: str) -> typer.Typer:
    """A typer group whose help is Markdown and whose type hints are plain."""
    return typer.Typer(help=help_text, no_args_is_help=True, rich_markup_mode="markdown")


_install()
