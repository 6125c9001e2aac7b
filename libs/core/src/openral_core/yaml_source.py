"""Safe YAML loading that remembers where every value came from.

The loader is ruamel's round-trip loader (which never builds arbitrary Python objects).
It turns the document into plain ``dict``/``list``/scalars and records the line and
column of every key and item, so later checks can point at the exact spot in the file.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.constructor import DuplicateKeyError
from ruamel.yaml.error import MarkedYAMLError
from ruamel.yaml.nodes import MappingNode, Node, SequenceNode

from openral_core.errors import Issue, ManifestError

PathKey = tuple[str | int, ...]


def format_field(path: PathKey) -> str:
    """Render a path such as ``("sim", "grippers", 0, "joint")`` as ``sim.grippers[0].joint``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


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
        ManifestError: The file cannot be read, is not valid YAML, has a duplicate key,
            or holds a non-finite number or a custom tag.
    """
    try:
        text = file.read_text(encoding="utf-8")
    except OSError as exc:
        issue = Issue(file, 0, 0, "", f"cannot read file: {exc.strerror}")
        raise ManifestError(file, [issue]) from None
    yaml = YAML(typ="rt")
    try:
        raw = yaml.load(text)
    except DuplicateKeyError:
        raise ManifestError(file, _duplicate_key_issues(file, yaml, text)) from None
    except MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (0, 0)
        problem = exc.problem or exc.context or "invalid YAML"
        issue = Issue(file, line, col, "", f"invalid YAML: {problem}")
        raise ManifestError(file, [issue]) from None
    document = LocatedDocument(file, None)
    issues: list[Issue] = []
    document.data = _plain(raw, (), document, issues)
    if issues:
        raise ManifestError(file, issues)
    return document


def _duplicate_key_issues(file: Path, yaml: YAML, text: str) -> list[Issue]:
    """Every repeated key in the document, naming the line of its first occurrence."""
    issues: list[Issue] = []
    pending: list[tuple[Node, PathKey]] = [(yaml.compose(text), ())]
    while pending:
        node, path = pending.pop()
        if isinstance(node, MappingNode):
            first_line: dict[str, int] = {}
            for key_node, value_node in node.value:
                key = str(key_node.value)
                mark = key_node.start_mark
                if key in first_line:
                    issues.append(
                        Issue(
                            file,
                            mark.line + 1,
                            mark.column + 1,
                            format_field((*path, key)),
                            f"duplicate key {key!r}: also defined on line {first_line[key]}; "
                            "each key may appear once",
                        )
                    )
                else:
                    first_line[key] = mark.line + 1
                pending.append((value_node, (*path, key)))
        elif isinstance(node, SequenceNode):
            pending.extend((item, (*path, i)) for i, item in enumerate(node.value))
    return sorted(issues, key=lambda issue: (issue.line, issue.column))


def _plain(node: Any, path: PathKey, doc: LocatedDocument, issues: list[Issue]) -> Any:
    """Convert ruamel nodes to plain Python, recording positions and rejecting oddities."""
    tag = getattr(getattr(node, "tag", None), "value", None)
    if tag is not None and tag.startswith("!") and not tag.startswith("!!"):
        issues.append(doc.issue(path, f"custom YAML tag {tag} is not allowed"))
        return None
    if isinstance(node, CommentedMap):
        result: dict[str, Any] = {}
        for key, (line, col) in _key_positions(node):
            child = (*path, str(key))
            doc.positions[child] = (line, col)
            if not isinstance(key, str):
                issues.append(doc.issue(child, f"keys must be strings, got {key!r}"))
            result[str(key)] = _plain(node[key], child, doc, issues)
        return result
    if isinstance(node, CommentedSeq):
        items: list[Any] = []
        for index, item in enumerate(node):
            line, col = node.lc.item(index)
            doc.positions[(*path, index)] = (line + 1, col + 1)
            items.append(_plain(item, (*path, index), doc, issues))
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
        return str(node)
    issues.append(doc.issue(path, f"unsupported YAML value {node!r} ({type(node).__name__})"))
    return None


def _key_positions(node: CommentedMap) -> Iterator[tuple[Any, tuple[int, int]]]:
    for key in node:
        line, col = node.lc.key(key)
        yield key, (line + 1, col + 1)
