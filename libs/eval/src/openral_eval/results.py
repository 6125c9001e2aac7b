"""``episodes.jsonl``: one line per finished episode, appended so nothing is lost.

Each result is one JSON line written with a single ``write`` on a file opened for
appending, then flushed to disk (``fsync``), as soon as its episode ends: a sweep killed at
any moment loses at most the episodes still running, never a written one. Reading back
(:meth:`EpisodeLog.done`) skips a last line cut off mid-write (and the next append
truncates it away), so ``--resume`` runs exactly the episodes that have no line.
When a sweep finishes, :meth:`EpisodeLog.sort` rewrites the file in plan order (a new file
renamed over the old one), so the same sweep always leaves the same file whatever the
order episodes finished in.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from dataclasses import asdict
from pathlib import Path

from openral_core.errors import OpenralError

from openral_eval.episode import EpisodeResult, EpisodeSpec

Key = tuple[str, int, str, tuple[tuple[str, str], ...]]


def result_key(line: dict[str, object]) -> Key:
    """The (scene, seed, policy, params) a written line is for."""
    params = line.get("params")
    pairs = (
        tuple(sorted((str(k), str(v)) for k, v in params.items()))
        if isinstance(params, dict)
        else ()
    )
    seed = line.get("seed")
    return (
        str(line.get("scene")),
        int(seed) if isinstance(seed, int) else -1,
        str(line.get("policy")),
        pairs,
    )


def read_results(path: Path) -> list[dict[str, object]]:
    """Every line of a finished sweep's ``episodes.jsonl``, checked to be a result.

    Raises:
        OpenralError: No such file, or a line (named ``path:line``) that is not a result.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise OpenralError(f"{path}: {error.strerror}; expected a sweep's results") from None
    lines = []
    for number, raw in enumerate(text.splitlines(), start=1):
        try:
            line = json.loads(raw)
            int(line["seed"]), str(line["scene"]), str(line["policy"]), int(line["steps"])
            str(line["trajectory_sha256"])
        except (ValueError, KeyError, TypeError):
            raise OpenralError(f"{path}:{number}: not a sweep's result line") from None
        lines.append(line)
    return lines


def spec_of(line: dict[str, object], **files: str | None) -> EpisodeSpec:
    """The episode a result line records, limited to the steps it took (so it ends where
    it ended: a success, the horizon or the limit); ``files`` sets ``video`` or
    ``dataset``."""
    scene, seed, policy, pairs = result_key(line)
    return EpisodeSpec(scene, seed, policy, pairs, int(str(line["steps"])), **files)


class EpisodeLog:
    """The results file of one sweep directory."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def done(self) -> dict[Key, dict[str, object]]:
        """Every complete line, by key (a line cut off by a kill is left out)."""
        if not self.path.exists():
            return {}
        lines: dict[Key, dict[str, object]] = {}
        for text in self.path.read_text().split("\n"):
            if not text.strip():
                continue
            try:
                line = json.loads(text)
            except json.JSONDecodeError:
                continue  # the tail of a write that a kill cut off
            if isinstance(line, dict):
                lines[result_key(line)] = line
        return lines

    def start(self, *, resume: bool) -> None:
        """Begin writing: keep the complete lines (``resume``) or start an empty file."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if not resume or not self.path.exists():
            self.path.write_text("")
            return
        data = self.path.read_bytes()
        end = data.rfind(b"\n") + 1  # a cut-off last line goes; whole lines stay
        if end != len(data):
            with self.path.open("r+b") as file:
                file.truncate(end)

    def append(self, result: EpisodeResult) -> None:
        """Write one result as one line, on disk before this returns."""
        line = (json.dumps(asdict(result), sort_keys=True) + "\n").encode()
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, line)
            os.fsync(fd)
        finally:
            os.close(fd)

    def sort(self, plan: Iterable[EpisodeSpec]) -> list[dict[str, object]]:
        """Rewrite the file in plan order (atomically) and return its lines in that order."""
        done = self.done()
        ordered = [done[spec.key] for spec in plan if spec.key in done]
        temporary = self.path.with_suffix(".jsonl.tmp")
        temporary.write_text("".join(json.dumps(line, sort_keys=True) + "\n" for line in ordered))
        temporary.replace(self.path)
        return ordered
