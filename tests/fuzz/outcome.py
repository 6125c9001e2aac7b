"""How one fuzz case ended, and the signature that groups equal findings.

* ``ok``: every stage passed.
* ``refused``: an :class:`OpenralError` whose every line is ``<fuzzed file>:<line>:<col>: …``
  (the one-line summary ``<file>: INVALID (n problem(s))`` above several issues is allowed).
* ``refused-unlocated``: an :class:`OpenralError` with a line that is not located there.
* ``traceback``: any other exception.
* ``hang``: the case ran longer than :data:`HANG_SECONDS`.
* ``crash``: the process running the case died (a segfault, an abort, out of memory).
"""

from __future__ import annotations

import re
import traceback
from dataclasses import asdict, dataclass
from enum import StrEnum
from pathlib import Path
from typing import Any

from openral_core.errors import OpenralError

HANG_SECONDS = 10.0
"""A case that takes longer than this is a hang."""


class Outcome(StrEnum):
    """The verdict on one case."""

    OK = "ok"
    REFUSED = "refused"
    UNLOCATED = "refused-unlocated"
    TRACEBACK = "traceback"
    HANG = "hang"
    CRASH = "crash"


FINDINGS = frozenset({Outcome.UNLOCATED, Outcome.TRACEBACK, Outcome.HANG, Outcome.CRASH})
"""Outcomes that are bugs: a campaign exits 1 and the test fails on any of them."""

Frame = tuple[str, int, str]
"""A stack frame as (file name, line, function)."""


@dataclass(frozen=True)
class Result:
    """The outcome of a case, the stage it ended in, its signature and the full detail."""

    outcome: Outcome
    stage: str
    signature: str = ""
    detail: str = ""
    seconds: float = 0.0

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (the worker's reply)."""
        return {**asdict(self), "outcome": self.outcome.value}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Result:
        """The inverse of :meth:`to_json`."""
        return cls(**{**data, "outcome": Outcome(data["outcome"])})


def _line_pattern(file: Path) -> re.Pattern[str]:
    names = "|".join(re.escape(str(p)) for p in {file, file.resolve()})
    located = rf"(?:{names}):[1-9]\d*:[1-9]\d*: "
    summary = rf"(?:{names}): INVALID \(\d+ problem\(s\)\)$"
    return re.compile(rf"^(?:{located}|{summary})")


def unlocated_lines(message: str, file: Path, *, unicode_breaks: bool = True) -> list[str]:
    """The lines of ``message`` that do not point into ``file`` (all of them when empty).

    Lines end at every line break Python knows (``str.splitlines``: also U+2028, U+0085,
    form feed, ...), as any reader that honours Unicode would split them; with
    ``unicode_breaks=False`` only at ``\n``.
    """
    lines = (message.splitlines() if unicode_breaks else message.split("\n")) or [""]
    pattern = _line_pattern(file)
    return [line for line in lines if not pattern.match(line)]


def _unlocated_signature(kind: str, where: str, message: str, file: Path) -> str | None:
    """The signature of an unlocated ``message``, or None when every line is located."""
    bad = unlocated_lines(message, file)
    if not bad:
        return None
    if not unlocated_lines(message, file, unicode_breaks=False):
        breaks = sorted({f"U+{ord(c):04X}" for c in message if c != "\n" and c.splitlines() != [c]})
        return f"{kind} @ {where}: a located line holds a line break ({', '.join(breaks)})"
    return f"{kind} @ {where}: {normalise(bad[0], file)}"


def normalise(text: str, file: Path) -> str:
    """``text`` with the file, paths, quoted strings and numbers blanked, for grouping."""
    text = text.replace(str(file), "<file>").replace(str(file.parent), "<dir>")
    text = re.sub(r"'[^']*'|\"[^\"]*\"", "'…'", text)
    text = re.sub(r"(?<![\w<])/[^\s:,;)]+", "<path>", text)
    text = re.sub(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", "N", text)
    return text[:100]


def innermost(frames: list[Frame]) -> str:
    """``package/module.py:line in function`` of the innermost openral frame (else the
    innermost frame), or ``?`` when there are none."""
    ours = [f for f in frames if "/src/openral_" in f[0]] or frames
    if not ours:
        return "?"
    name, line, function = ours[-1]
    short = name.split("/src/", 1)[-1] if "/src/" in name else Path(name).name
    return f"{short}:{line} in {function}"


def classify(error: BaseException, stage: str, file: Path) -> Result:
    """The :class:`Result` of a case that ended with ``error`` in ``stage``."""
    frames = [
        (f.filename, f.lineno or 0, f.name) for f in traceback.extract_tb(error.__traceback__)
    ]
    where = innermost(frames)
    kind = type(error).__name__
    if isinstance(error, OpenralError):
        message = str(error)
        signature = _unlocated_signature(kind, where, message, file)
        if signature is None:
            return Result(Outcome.REFUSED, stage, kind, message)
        return Result(Outcome.UNLOCATED, stage, signature, message)
    detail = "".join(traceback.format_exception(error))
    return Result(Outcome.TRACEBACK, stage, f"{kind} @ {where}", detail)


def classify_lines(lines: list[str], stage: str, file: Path) -> Result:
    """The :class:`Result` of an error seen only as printed lines (the ``robot check`` CLI)."""
    message = "\n".join(lines)
    signature = _unlocated_signature("printed", "robot check", message, file)
    if signature is None:
        return Result(Outcome.REFUSED, stage, "printed", message)
    return Result(Outcome.UNLOCATED, stage, signature, message)


_DUMP_FRAME = re.compile(r'^\s*File "([^"]+)", line (\d+) in (\S+)')


def dumped_frames(dump: str) -> list[Frame]:
    """Frames, outermost first, of the thread of a :mod:`faulthandler` dump that was running
    a case (the one with a frame in ``tests/fuzz/stages.py``; else the first thread)."""
    blocks: list[list[Frame]] = []
    for line in dump.splitlines():
        if line.startswith(("Current thread", "Thread", "Stack")):
            blocks.append([])
            continue
        match = _DUMP_FRAME.match(line)
        if match:
            if not blocks:
                blocks.append([])
            blocks[-1].append((match[1], int(match[2]), match[3]))
    running = [b for b in blocks if any(f[0].endswith("fuzz/stages.py") for f in b)]
    chosen = (running or blocks or [[]])[0]
    return list(reversed(chosen))  # faulthandler writes the most recent call first


def hang(stage: str, dump: str, seconds: float) -> Result:
    """The :class:`Result` of a case that overran, from its faulthandler dump."""
    where = innermost(dumped_frames(dump))
    return Result(Outcome.HANG, stage, f"over {HANG_SECONDS:g} s @ {where}", dump, seconds)


def crash(stage: str, dump: str, cause: str) -> Result:
    """The :class:`Result` of a case whose process died or was killed for its memory.

    Args:
        stage: The stage the case was in.
        dump: What faulthandler wrote (the stack at a fatal signal), if anything.
        cause: How the process ended, when the dump does not say.
    """
    fatal = next((ln for ln in dump.splitlines() if ln.startswith("Fatal Python error")), "")
    what = fatal.removeprefix("Fatal Python error: ") or cause
    where = innermost(dumped_frames(dump))
    return Result(Outcome.CRASH, stage, f"{what} @ {where}", dump or cause)
