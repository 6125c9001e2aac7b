"""Safe YAML loading that remembers where every value came from.

The text first passes :mod:`openral_core.yaml_guard` (size, encoding, control characters,
nesting, aliases, tags, merge and duplicate keys, long integers). Only then does ruamel's
round-trip loader (which never builds arbitrary Python objects) parse it; the document is
turned into plain ``dict``/``list``/scalars with the line and column of every key and item,
so later checks can point at the exact spot in the file. A string that aliases repeat is
converted once and shared, not copied for each alias.

A process remembers the documents it parsed, by file name and SHA-256 of the text (at most
:data:`MAX_REMEMBERED_CHARS` of text), and hands out copies: parsing takes 25-90 ms per
manifest in ruamel's pure-Python loader, a copy well under 1 ms, and a tool or test that
loads the same files again and again (``schema-export``, ``robot check`` of a folder, a
sweep) need not parse them again. A changed file has another digest, so it is parsed
afresh; a file that fails is never remembered.
"""

from __future__ import annotations

import copy
import hashlib
import math
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import MarkedYAMLError, YAMLError

from openral_core.errors import Issue, ManifestError, PathKey, format_field
from openral_core.yaml_guard import read_text, scan_events, syntax_issue

__all__ = ["LocatedDocument", "PathKey", "format_field", "load_located"]

MAX_REMEMBERED_CHARS = 1 << 22
"""Most characters of source text whose parsed documents a process keeps (4 Mi)."""
_PARSED: OrderedDict[tuple[str, str], tuple[LocatedDocument, int]] = OrderedDict()
"""Parsed documents by (file name, text digest), least recently used first, each with
its text's length [chars]."""


@dataclass
class LocatedDocument:
    """A parsed document plus the 1-based (line, column) of each of its nodes."""

    file: Path
    data: Any
    positions: dict[PathKey, tuple[int, int]] = field(default_factory=dict)

    def position(self, path: PathKey) -> tuple[int, int]:
        """Position of the deepest known node on ``path`` (the document start as a fallback)."""
        for end in range(len(path), -1, -1):
            found = self.positions.get(tuple(path[:end]))
            if found is not None:
                return found
        return (1, 1)

    def issue(self, path: PathKey, message: str) -> Issue:
        """Build an :class:`Issue` located at ``path``."""
        line, column = self.position(path)
        return Issue(self.file, line, column, format_field(path), message)


def load_located(file: Path) -> LocatedDocument:
    """Parse ``file`` into a :class:`LocatedDocument`.

    Raises:
        ManifestError: The file cannot be read, breaks a limit of
            :mod:`openral_core.yaml_guard`, is not valid YAML, or holds a non-finite number
            or a value of a type the contract has no use for (dates, ...).
    """
    text = read_text(file)
    key = (str(file), hashlib.sha256(text.encode("utf-8")).hexdigest())
    kept = _PARSED.get(key)
    if kept is None:
        kept = _PARSED[key] = (_parse(file, text), len(text))
        while len(_PARSED) > 1 and sum(size for _, size in _PARSED.values()) > MAX_REMEMBERED_CHARS:
            _PARSED.popitem(last=False)
    _PARSED.move_to_end(key)
    parsed = kept[0]
    return LocatedDocument(file, copy.deepcopy(parsed.data), dict(parsed.positions))


def _parse(file: Path, text: str) -> LocatedDocument:
    """The document of ``text`` (read from ``file``), checked and parsed (see load_located)."""
    scan_events(file, text)
    try:
        raw = YAML(typ="rt").load(text)
    except MarkedYAMLError as error:  # YAML 1.2 that libyaml's 1.1 parser let through
        raise ManifestError(file, [syntax_issue(file, error)]) from None
    except (YAMLError, ValueError, RecursionError) as error:  # the scan should prevent these
        issue = Issue(file, 1, 1, "", f"cannot be read as YAML ({type(error).__name__})")
        raise ManifestError(file, [issue]) from None
    document = LocatedDocument(file, None)
    issues: list[Issue] = []
    document.data = _plain(raw, (), document, issues, {})
    if issues:
        raise ManifestError(file, issues)
    return document


def _plain(
    node: Any, path: PathKey, doc: LocatedDocument, issues: list[Issue], strings: dict[int, str]
) -> Any:
    """Convert ruamel nodes to plain Python, recording positions and rejecting oddities.

    ``strings`` maps the id of each ruamel string converted so far (an anchored one is a
    ``str`` subclass, shared by its aliases) to its plain ``str``, so none is copied twice.
    """
    if isinstance(node, CommentedMap):
        result: dict[str, Any] = {}
        for key, (line, col) in _key_positions(node):
            child = (*path, str(key))
            doc.positions[child] = (line, col)
            if not isinstance(key, str):
                issues.append(doc.issue(child, f"keys must be strings, got {key!r}"))
            result[str(key)] = _plain(node[key], child, doc, issues, strings)
        return result
    if isinstance(node, CommentedSeq):
        items: list[Any] = []
        for index, item in enumerate(node):
            line, col = node.lc.item(index)
            doc.positions[(*path, index)] = (line + 1, col + 1)
            items.append(_plain(item, (*path, index), doc, issues, strings))
        return items
    if isinstance(node, bool) or node is None:
        return node
    if isinstance(node, int):
        return int(node)
    if isinstance(node, float):
        if not math.isfinite(node):
            issues.append(doc.issue(path, f"expected a finite number, got {node}"))
        return float(node)
    if isinstance(node, str):
        if type(node) is str:
            return node
        plain = strings.get(id(node))
        if plain is None:
            plain = strings[id(node)] = str(node)
        return plain
    issues.append(doc.issue(path, f"unsupported YAML value {node!r} ({type(node).__name__})"))
    return None


def _key_positions(node: CommentedMap) -> Iterator[tuple[Any, tuple[int, int]]]:
    for key in node:
        line, col = node.lc.key(key)
        yield key, (line + 1, col + 1)
