"""Every line the CLI prints goes through here; data is never read as rich markup.

Paths, robot ids, topic names and error messages may contain ``[brackets]`` or
``:emoji:`` codes. A console that parses markup would crash on ``[/x]`` or restyle
``[bold]``, so the consoles here parse neither. Colour is applied explicitly:
:func:`line` and :func:`styled` build :class:`~rich.text.Text` from plain and
``(text, style)`` pieces, and table cells or titles given as ``str`` render verbatim on
these consoles. rich's number/path colouring is off unless a call asks for it
(``print(..., highlight=True)`` or :func:`highlighted`); it colours, never parses.

rich is imported when something is first printed, not when the CLI starts (~25 ms with
cached bytecode, ~0.15 s without): ``deploy sim`` prints nothing before its graph is live.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress
    from rich.status import Status
    from rich.text import Text

__all__ = [
    "LazyConsole",
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


PIPED_WIDTH = 1000
"""Columns a console has when its output is not a terminal and ``$COLUMNS`` is unset."""


class LazyConsole:
    """A rich :class:`~rich.console.Console` (no markup, highlighting or emoji codes) made on
    first use."""

    def __init__(self, *, stderr: bool) -> None:
        self._stderr = stderr
        self._console: Console | None = None

    @property
    def console(self) -> Console:
        """The console itself (made now if it was not yet)."""
        if self._console is None:
            from rich.console import Console

            self._console = Console(
                stderr=self._stderr, soft_wrap=True, markup=False, highlight=False, emoji=False
            )
            if not self._console.is_terminal and "COLUMNS" not in os.environ:
                # Piped or redirected: no screen to fit, so tables keep their natural
                # width instead of rich's 80-column default (which wraps their cells).
                self._console.width = PIPED_WIDTH
        return self._console

    def print(self, *objects: Any, **options: Any) -> None:
        """:meth:`rich.console.Console.print`."""
        self.console.print(*objects, **options)


out = LazyConsole(stderr=False)
"""Standard output: results, tables."""
err = LazyConsole(stderr=True)
"""Standard error: problems and summaries of failures."""

Piece = str | tuple[str, str]
"""Plain text, or ``(text, style)`` such as ``("OK", "green")``."""


def styled(text: str, style: str) -> Text:
    """``text`` in ``style`` (e.g. ``"red"``), never parsed for markup."""
    from rich.text import Text

    return Text(text, style=style)


def line(*pieces: Piece) -> Text:
    """One line from plain and styled pieces: ``line(path, ": ", ("OK", "green"))``."""
    from rich.text import Text

    return Text.assemble(*pieces)


def highlighted(text: Text) -> Text:
    """``text`` with rich's number/path/boolean colouring added (what ``highlight=True`` does)."""
    from rich.highlighter import ReprHighlighter

    return ReprHighlighter()(text)


def error(message: str) -> None:
    """Print ``error: <message>`` on stderr, ``error:`` in bold red."""
    err.print(line(("error:", "bold red"), " ", message))


def progress() -> Progress:
    """A transient progress bar on :data:`out` whose task descriptions print verbatim."""
    from rich.progress import (
        BarColumn,
        Progress,
        TaskProgressColumn,
        TextColumn,
        TimeRemainingColumn,
    )

    return Progress(
        TextColumn("{task.description}", style="progress.description", markup=False),
        BarColumn(),
        TaskProgressColumn(),
        TimeRemainingColumn(),
        console=out.console,
        transient=True,
    )


def status(text: str) -> Status:
    """A spinner status line on :data:`out`; update it with :func:`line` or :func:`styled`."""
    from rich.text import Text

    return out.console.status(Text(text))
