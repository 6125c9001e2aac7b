"""How a tutorial's shown output is compared with what a command really printed.

A tutorial shows a command's output in full: every line it prints, in order. Two kinds of
looseness are allowed, both visible on the page:

- Within a line, ``…`` stands for any text (a temporary path, a time, a count), runs of
  white space compare as one space, and a run of one horizontal box-drawing character
  (``━━━``) compares as one, so a table column may be wider or narrower than shown.
- A line holding only :data:`ELISION` stands for any number of lines (none included). It
  is the one way to leave lines out, so a reader always sees where something was cut.
"""

from __future__ import annotations

import re
from functools import cache

ELISION = "⋮"
"""A shown line made of this alone stands for any number of printed lines."""
_RULES = "━─═╌┄"
_RULE_RUN = re.compile(f"([{_RULES}])\\1+")


def normalise(line: str) -> str:
    """``line`` with white space runs and box-drawing rule runs collapsed to one."""
    return _RULE_RUN.sub(r"\1", " ".join(line.split()))


@cache
def _pattern(shown: str) -> re.Pattern[str]:
    parts = normalise(shown).split("…")
    return re.compile(".*?".join(re.escape(part) for part in parts), re.DOTALL)


def line_matches(shown: str, printed: str) -> bool:
    """Whether one printed line is what the shown line says (``…`` = any text)."""
    return _pattern(shown).fullmatch(normalise(printed)) is not None


def printed_lines(output: str) -> list[str]:
    """The lines of ``output`` a reader sees (blank lines and trailing space dropped)."""
    return [line.rstrip() for line in output.splitlines() if line.strip()]


def match_prefix(shown: list[str], printed: list[str]) -> int | None:
    """How many printed lines the shown lines account for from the start, or None.

    The shown lines must match the first printed lines one for one, except that an
    :data:`ELISION` line takes up any number of lines (as few as lets the rest match).
    """
    return _match(tuple(shown), tuple(printed), 0, 0)


def match_all(shown: list[str], printed: list[str]) -> bool:
    """Whether the shown lines account for every printed line."""
    return _match(tuple(shown), tuple(printed), 0, 0, whole=True) is not None


def _match(
    shown: tuple[str, ...], printed: tuple[str, ...], i: int, j: int, *, whole: bool = False
) -> int | None:
    if i == len(shown):
        return j if not whole or j == len(printed) else None
    if shown[i].strip() == ELISION:
        for skip in range(j, len(printed) + 1):
            end = _match(shown, printed, i + 1, skip, whole=whole)
            if end is not None:
                return end
        return None
    if j < len(printed) and line_matches(shown[i], printed[j]):
        return _match(shown, printed, i + 1, j + 1, whole=whole)
    return None


def mismatch(shown: list[str], printed: list[str]) -> str:
    """A short account of where the shown lines and the printed ones part."""
    j = 0
    for i, line in enumerate(shown):
        if line.strip() == ELISION:
            return f"shown lines after the elision at shown line {i + 1} are not printed in order"
        if j >= len(printed):
            return f"shown line {i + 1} {line!r} was never printed (output ended)"
        if not line_matches(line, printed[j]):
            return f"shown line {i + 1} {line!r} differs from printed line {j + 1} {printed[j]!r}"
        j += 1
    cut = f"show it, or mark the cut with {ELISION}"
    return f"printed line {j + 1} {printed[j]!r} is not shown ({cut})"
