"""The Markdown that renders ``--help``: rich's, with raw HTML read as plain text.

rich's :class:`~rich.markdown.Markdown` parses CommonMark with raw HTML on and then drops
every HTML tag it meets, so a placeholder such as ``robots/<id>/robot.yaml`` printed as
``robots//robot.yaml``. Help text never holds HTML, only placeholders, so here a ``<...>``
is text. Imported only when help is printed: the CLI starts without rich.
"""

from __future__ import annotations

from typing import Any

from markdown_it import MarkdownIt
from rich.markdown import Markdown

__all__ = ["PlainAngleMarkdown"]


class PlainAngleMarkdown(Markdown):
    """rich's Markdown with raw HTML off: ``<id>`` prints as ``<id>``."""

    def __init__(self, markup: str, *args: Any, **kwargs: Any) -> None:
        super().__init__(markup, *args, **kwargs)
        parser = MarkdownIt("commonmark", {"html": False}).enable(["strikethrough", "table"])
        self.parsed = parser.parse(markup)
