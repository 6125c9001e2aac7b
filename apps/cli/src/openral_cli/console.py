"""Every line the CLI prints goes through here; data is never read as rich markup.

Paths, robot ids, topic names and error messages may contain ``[brackets]`` or
``:emoji:`` codes. A console that parses markup would crash on ``[/x]`` or restyle
``[bold]``, so the consoles here parse neither. Colour is applied explicitly:
:func:`line` and :func:`styled` build :class:`~rich.text.Text` from plain and
``(text, style)`` pieces, and table cells or titles given as ``str`` render verbatim on
these consoles. rich's number/path colouring is off unless a call asks for it
(``print(..., highlight=True)`` or :func:`highlighted`); it colours, never parses.
"""

from __future__ import annotations

from rich.console import Console
from rich.highlighter import ReprHighlighter
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeRemainingColumn
from rich.status import Status
from rich.text import Text

__all__ = [
    "Piece",
    "err",
    "error",
    "highlighted",
    "line",
    "out",
    "progress",
    "status",
    "styled",
]

out = Console(soft_wrap=True, markup=False, highlight=False, emoji=False)
"""Standard output: results, tables."""
err = Console(stderr=True, soft_wrap=True, markup=False, highlight=False, emoji=False)
"""Standard error: problems and summaries of failures."""

Piece = str | tuple[str, str]
"""Plain text, or ``(text, style)`` such as ``("OK", "green")``."""


def styled(text: str, style: str) -> Text:
    """``text`` in ``style`` (e.g. ``"red"``), never parsed for markup."""
    return Text(text, style=style)


def line(*pieces: Piece) -> Text:
    """One line from plain and styled pieces: ``line(path, ": ", ("OK", "green"))``."""
    return Text.assemble(*pieces)


def highlighted(text: Text) -> Text:
    """``text`` with rich's number/path/boolean colouring added (what ``highlight=True`` does)."""
    return ReprHighlighter()(text)


def error(message: str) -> None:
    """Print ``error: <message>`` on stderr, ``error:`` in bold red."""
    err.print(line(("error:", "bold red"), " ", message))


def progress() -> Progress:
    """A transient progress bar on :data:`out` whose task descriptions print verbatim."""
    return Progress(
        TextColumn("{task.description}", style="progress.description", markup=False),
        BarColumn(),
        TaskProgressColumn(),
        TimeRemainingColumn(),
        console=out,
        transient=True,
    )


def status(text: str) -> Status:
    """A spinner status line on :data:`out`; update it with :func:`line` or :func:`styled`."""
    return out.status(Text(text))
