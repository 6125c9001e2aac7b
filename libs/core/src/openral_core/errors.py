"""Error types shared by every openral library.

Every error raised on purpose derives from :class:`OpenralError`, so the CLI can turn it
into one clear message and exit code instead of a traceback.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

PathKey = tuple[str | int, ...]
"""Where a value sits in a document: keys and list indices from the root."""


def format_field(path: PathKey) -> str:
    """Render a path such as ``("sim", "grippers", 0, "joint")`` as ``sim.grippers[0].joint``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


def parse_field(text: str) -> PathKey:
    """The inverse of :func:`format_field`: ``sim.grippers[0].joint`` → its path."""
    path: list[str | int] = []
    for part in text.split("."):
        name, *indices = part.split("[")
        if name:
            path.append(name)
        path.extend(int(index.rstrip("]")) for index in indices)
    return tuple(path)


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """`` (did you mean joint1?)`` naming the closest of ``candidates`` to a misspelt
    ``name`` (difflib's ratio of at least 0.6; up to three within 0.05 of the best), else ``''``.

    The one helper every "not found" message uses: unknown keys, joints, cameras, bodies,
    sites and scene cameras.
    """
    close = difflib.get_close_matches(name, [c for c in candidates if c != name], n=3)
    if not close:
        return ""
    best = _likeness(name, close[0])
    close = [c for c in close if _likeness(name, c) >= best - 0.05]
    names = close[0] if len(close) == 1 else f"{', '.join(close[:-1])} or {close[-1]}"
    return f" (did you mean {names}?)"


def _likeness(a: str, b: str) -> float:
    return difflib.SequenceMatcher(None, a, b).ratio()


class OpenralError(Exception):
    """Root of every error openral raises on purpose."""


@dataclass(frozen=True, slots=True)
class Issue:
    """One problem found in a file, located as precisely as the file allows.

    Attributes:
        file: The file the problem is in.
        line: 1-based line number, or 0 when the position is unknown.
        column: 1-based column number, or 0 when the position is unknown.
        field: Dotted field path such as ``sim.grippers[0].joint`` ('' for the document).
        message: What is wrong and what was expected.
    """

    file: Path
    line: int
    column: int
    field: str
    message: str

    def format(self) -> str:
        """Render as ``file:line:col: field.path: message``, always one printable line."""
        where = escaped(f"{self.file}:{self.line}:{self.column}: {self.field or '<document>'}")
        return f"{where}: {one_line(self.message)}"


def one_line(text: str) -> str:
    """A message of several lines (MuJoCo's compiler writes two) joined with ``; ``, then
    :func:`escaped`, so a terminal shows exactly one line."""
    return escaped("; ".join(part.strip() for part in text.splitlines() if part.strip()))


def escaped(text: str) -> str:
    """``text`` with every unprintable character (a U+2028 in a key, an escape code)
    written as its Python escape."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


class ManifestError(OpenralError):
    """A manifest or scene file failed to load; carries every issue found in it."""

    def __init__(self, file: Path, issues: Sequence[Issue]) -> None:
        self.file = file
        self.issues = tuple(issues)
        lines = "\n".join(issue.format() for issue in self.issues)
        if len(self.issues) == 1:  # one problem: its located line says it all
            super().__init__(lines)
        else:
            super().__init__(f"{file}: INVALID ({len(self.issues)} problem(s))\n{lines}")


class UnknownRobot(OpenralError):
    """A robot id that has no folder under robots/."""

    def __init__(self, robot_id: str, known: Sequence[str]) -> None:
        self.robot_id = robot_id
        self.known = tuple(known)
        super().__init__(
            f"unknown robot {robot_id!r}; known robots: {', '.join(self.known) or '(none)'}. "
            "Run `openral robot list` to see them."
        )


class StaleTables(OpenralError):
    """A robot's generated tables were not made from its manifest as it reads now."""

    def __init__(self, table: str, manifest: str, problem: str | None = None) -> None:
        self.table = table
        self.manifest = manifest
        why = one_line(problem) if problem else f"stale: made from an earlier {manifest}"
        super().__init__(escaped(f"{table}: {why}; run `just schema-export`"))
