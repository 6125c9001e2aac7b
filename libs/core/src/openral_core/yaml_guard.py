"""The limits a manifest or scene file must respect before any of it is built.

A robot.yaml or scene file can come from anyone, so the reader refuses, with one located
line each, what would otherwise cost unbounded time or memory or end in a traceback:

- :func:`read_text`: files over :data:`MAX_FILE_BYTES`, anything but a regular file, bytes
  that are not UTF-8, and control characters YAML does not allow;
- :func:`scan_events`: one pass over the document's event stream from libyaml's C parser
  (through PyYAML: explicit stacks, so no input makes it recurse; 0.4 ms for the franka
  manifest, where ruamel's pure-Python parser takes 15 ms) that refuses nesting deeper
  than :data:`MAX_DEPTH`, more than :data:`MAX_NODES` values (aliases included), aliases
  that would expand the document (a "billion laughs" bomb, or many aliases to one long
  string) or that refer to their own node, tags, directives, merge keys (``<<``), keys
  that are not plain scalars, repeated keys, more than one document and integers longer
  than :data:`MAX_INT_DIGITS`.

Only a document that passed both is handed to ruamel's loader (YAML 1.2 values and the
position of every key). The scan counts an alias as the size of the node it names, in
constant time: its nodes and the characters of every scalar (keys included) in it.
Aliases may add at most :data:`MAX_ALIAS_NODES` nodes (and :data:`ALIAS_FACTOR` times the
nodes written) and :data:`MAX_ALIAS_CHARS` characters, so a loaded document holds at most
~3 Mi characters of text (the file's own 1 MiB plus 2 Mi from aliases) whatever the file;
a bomb is refused at the alias that crosses a bound, after reading only the text before
it, never by expanding it.
"""

from __future__ import annotations

import re
import stat
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import yaml
from yaml.error import MarkedYAMLError, YAMLError
from yaml.events import (
    AliasEvent,
    CollectionStartEvent,
    DocumentStartEvent,
    Event,
    MappingStartEvent,
    NodeEvent,
    ScalarEvent,
)

from openral_core.errors import Issue, ManifestError, PathKey, format_field

MAX_FILE_BYTES = 1 << 20
"""Largest file accepted [bytes] (1 MiB; the largest manifest in robots/ is ~10 KiB)."""
MAX_DEPTH = 32
"""Deepest nesting of mappings and lists accepted (manifests nest about 5 deep)."""
MAX_NODES = 20_000
"""Most values written in one file, aliases included (the largest manifest in robots/ has
~600; ruamel's loader reads some 15,000-40,000 a second, so this bounds a load to ~1 s)."""
MAX_ALIAS_NODES = 100_000
"""Most nodes that aliases may add to a document, whatever its size."""
MAX_ALIAS_CHARS = 1 << 21
"""Most characters of scalar text that aliases may add to a document (2 Mi; a manifest's
aliases repeat a few limits or names, some hundred characters)."""
ALIAS_FACTOR = 10
"""Aliases may add at most this many times the number of nodes written in the file."""
MAX_INT_DIGITS = 100
"""Longest integer accepted [digits] (Python refuses to convert past 4,300)."""

_NOT_PRINTABLE = re.compile(
    "[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]"
)
"""Characters YAML 1.2 does not allow in a stream (C0/C1 controls, surrogates, U+FFFE/F)."""
_LONG_INT = re.compile(r"[-+]?[0-9][0-9_]*")
_FLOW_TOKENS = re.compile(
    r"""'(?:[^']|'')*'|"(?:[^"\\]|\\.)*"|(?:^|(?<=\s))#[^\n]*|[\[\]{}]""", re.M
)
"""Quoted scalars and comments (skipped) and flow brackets (counted) for :func:`read_text`."""
_OUTSIDE_FILE = (0, 0)


def read_text(file: Path) -> str:
    """The text of ``file``, checked for size, type, encoding and control characters.

    Raises:
        ManifestError: One located line saying what is wrong and what is expected.
    """
    try:
        info = file.stat()
        if not stat.S_ISREG(info.st_mode):
            _refuse(file, _OUTSIDE_FILE, "not a regular file; expected a YAML file")
        if info.st_size > MAX_FILE_BYTES:
            _refuse(file, (1, 1), _too_big(info.st_size))
        with file.open("rb") as handle:
            data = handle.read(MAX_FILE_BYTES + 1)
    except OSError as error:
        _refuse(file, _OUTSIDE_FILE, f"cannot read file: {error.strerror}")
    if len(data) > MAX_FILE_BYTES:  # grew while we looked
        _refuse(file, (1, 1), _too_big(len(data)))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        where = _position_of_byte(data, error.start)
        byte = data[error.start]
        _refuse(file, where, f"byte 0x{byte:02x} is not UTF-8; save the file as UTF-8")
    text = text.removeprefix("\ufeff")
    bad = _NOT_PRINTABLE.search(text)
    if bad is not None:
        code = ord(bad.group())
        message = (
            f"character U+{code:04X} is not allowed in YAML; only tab, line feed and "
            "carriage return of the control characters are"
        )
        _refuse(file, _position_of_char(text, bad.start()), message)
    _check_flow_depth(file, text)
    return text


def _check_flow_depth(file: Path, text: str) -> None:
    """Refuse ``[``/``{`` nesting past :data:`MAX_DEPTH` before the parser sees it.

    ruamel's scanner looks up to 1024 characters ahead for a possible key in flow context,
    so deep flow nesting costs it quadratic time; counting brackets here costs a regex.
    A bracket inside a plain scalar counts too (a plain scalar rarely holds 32 of them).
    """
    depth = 0
    for match in _FLOW_TOKENS.finditer(text):
        token = match.group()
        if token in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                where = _position_of_char(text, match.start())
                _refuse(file, where, f"nested deeper than {MAX_DEPTH} levels")
        elif token in "]}":
            depth = max(depth - 1, 0)


@dataclass
class _Frame:
    """An open mapping or list while scanning, and what has been seen in it."""

    path: PathKey
    is_mapping: bool
    anchor: str | None
    size: int = 1
    """Nodes in this collection so far, aliases expanded (itself included)."""
    chars: int = 0
    """Characters of the scalars in this collection so far, aliases expanded."""
    children: int = 0
    key: str | int | None = None
    """The key whose value comes next (mappings)."""
    keys: dict[str, int] = field(default_factory=dict)
    """Keys seen so far → the line they were written on (mappings)."""

    @property
    def expects_key(self) -> bool:
        return self.is_mapping and self.children % 2 == 0

    def child_path(self) -> PathKey:
        if not self.is_mapping:
            return (*self.path, self.children)
        return self.path if self.expects_key or self.key is None else (*self.path, self.key)


@dataclass
class _Scan:
    """State of one pass over a document's events."""

    file: Path
    frames: list[_Frame] = field(default_factory=list)
    anchors: dict[str, tuple[int, int]] = field(default_factory=dict)
    """Finished anchored nodes → their expanded size: (nodes, characters of scalars)."""
    open_anchors: set[str] = field(default_factory=set)
    written: int = 0
    """Nodes written in the file (aliases not included)."""
    aliases: int = 0
    expanded: int = 0
    """Nodes that aliases add to the document."""
    expanded_chars: int = 0
    """Characters of scalar text that aliases add to the document."""
    first_alias: AliasEvent | None = None
    documents: int = 0
    issues: list[Issue] = field(default_factory=list)
    stopped: bool = False
    """A resource limit was hit: the rest of the stream is not read."""

    def issue(self, event: Event, path: PathKey, message: str, *, fatal: bool = False) -> None:
        line, column = _position(event)
        self.issues.append(Issue(self.file, line, column, format_field(path), message))
        self.stopped = self.stopped or fatal


def _position(event: Event) -> tuple[int, int]:
    """(line, column) of ``event``'s start, 1-based (every event the parser gives has one)."""
    mark = event.start_mark
    return (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)


class MarkedError(Protocol):
    """A YAML syntax error with where it was found: PyYAML's and ruamel's alike."""

    problem: str | None
    context: str | None

    @property
    def problem_mark(self) -> Any: ...

    @property
    def context_mark(self) -> Any: ...


def syntax_issue(file: Path, error: MarkedError) -> Issue:
    """The located issue of a YAML syntax error (PyYAML's or ruamel's; 0-based marks)."""
    mark = error.problem_mark or error.context_mark
    line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
    problem = error.problem or error.context or "invalid YAML"
    return Issue(file, line, column, "", f"invalid YAML: {problem}")


def scan_events(file: Path, text: str) -> None:
    """Check the event stream of ``text`` against the limits of the module docstring.

    Raises:
        ManifestError: Every problem found (a resource limit stops the scan at once).
    """
    scan = _Scan(file)
    try:
        for event in _events(text):
            _visit(scan, event)
            if scan.stopped:
                break
        _check_alias_ratio(scan)
    except MarkedYAMLError as error:
        scan.issues.append(syntax_issue(file, error))
    except YAMLError as error:  # reader-level problems the text checks did not foresee
        scan.issues.append(Issue(file, 1, 1, "", f"invalid YAML: {error}"))
    if scan.issues:
        raise ManifestError(file, sorted(scan.issues, key=lambda i: (i.line, i.column)))


def _events(text: str) -> Iterator[Event]:
    yield from yaml.parse(text, Loader=yaml.CSafeLoader)


def _visit(scan: _Scan, event: Event) -> None:
    if isinstance(event, DocumentStartEvent):
        _document_start(scan, event)
    elif isinstance(event, NodeEvent):
        _node(scan, event)
    elif scan.frames and type(event).__name__ in ("MappingEndEvent", "SequenceEndEvent"):
        frame = scan.frames.pop()
        if frame.anchor is not None:
            scan.open_anchors.discard(frame.anchor)
            scan.anchors[frame.anchor] = (frame.size, frame.chars)
        _finish_child(scan, (frame.size, frame.chars), None)


def _document_start(scan: _Scan, event: DocumentStartEvent) -> None:
    scan.documents += 1
    if scan.documents > 1:
        scan.issue(event, (), "a second YAML document; a file holds exactly one")
    if event.tags or (event.version is not None and tuple(event.version) != (1, 2)):
        scan.issue(event, (), "%YAML/%TAG directives are not allowed; these files are YAML 1.2")


def _node(scan: _Scan, event: NodeEvent) -> None:
    parent = scan.frames[-1] if scan.frames else None
    path = parent.child_path() if parent else ()
    is_key = parent is not None and parent.expects_key
    tag: Any = getattr(event, "tag", None)
    if tag is not None:
        scan.issue(event, path, f"YAML tags ({tag}) are not allowed; write the plain value")
    if isinstance(event, AliasEvent):
        scan.aliases += 1
        _count_value(scan, event, path)
        if not scan.stopped:
            _alias(scan, event, path, is_key)
        return
    scan.written += 1
    _count_value(scan, event, path)
    if event.anchor is not None:
        scan.open_anchors.add(event.anchor)
    if isinstance(event, CollectionStartEvent):
        if is_key:
            scan.issue(event, path, "a key must be a plain string, not a mapping or list")
        if len(scan.frames) >= MAX_DEPTH:
            scan.issue(event, path, f"nested deeper than {MAX_DEPTH} levels", fatal=True)
        is_mapping = isinstance(event, MappingStartEvent)
        scan.frames.append(_Frame(path, is_mapping, event.anchor))
        return
    assert isinstance(event, ScalarEvent)
    if is_key and parent is not None:
        _key(scan, event, parent)
    if not event.style and _LONG_INT.fullmatch(event.value):  # plain ("" from libyaml)
        digits = sum(ch.isdigit() for ch in event.value)
        if digits > MAX_INT_DIGITS:
            message = f"an integer of {digits} digits; at most {MAX_INT_DIGITS} are accepted"
            scan.issue(event, path, message)
    size = (1, len(event.value))
    if event.anchor is not None:
        scan.open_anchors.discard(event.anchor)
        scan.anchors[event.anchor] = size
    _finish_child(scan, size, event.value if is_key else None)


def _count_value(scan: _Scan, event: NodeEvent, path: PathKey) -> None:
    """Refuse the value past :data:`MAX_NODES` written in the file (aliases count: each one
    costs the parser as much as a written value)."""
    if scan.written + scan.aliases > MAX_NODES:
        scan.issue(event, path, f"more than {MAX_NODES} values in one file", fatal=True)


def _key(scan: _Scan, event: ScalarEvent, frame: _Frame) -> None:
    key, line = event.value, _position(event)[0]
    if key == "<<" and not event.style:
        message = "merge keys (<<) are not supported; write the keys out"
        scan.issue(event, frame.path, message)
    elif key in frame.keys:
        message = (
            f"duplicate key {key!r}: also defined on line {frame.keys[key]}; "
            "each key may appear once"
        )
        scan.issue(event, (*frame.path, key), message)
    frame.keys.setdefault(key, line)


def _alias(scan: _Scan, event: AliasEvent, path: PathKey, is_key: bool) -> None:
    name = event.anchor
    if is_key:
        scan.issue(event, path, "an alias cannot be a key; write the key out")
    if name in scan.open_anchors:
        scan.issue(event, path, f"alias *{name} refers to the node that contains it")
        _finish_child(scan, (1, 0), None)
        return
    size = scan.anchors.get(name) if name is not None else None
    if size is None:
        scan.issue(event, path, f"alias *{name} names no anchor defined before it")
        size = (1, 0)
    scan.expanded += size[0]
    scan.expanded_chars += size[1]
    scan.first_alias = scan.first_alias or event
    if scan.expanded > MAX_ALIAS_NODES:
        message = f"aliases expand this document by more than {MAX_ALIAS_NODES} nodes"
        scan.issue(event, path, message, fatal=True)
    elif scan.expanded_chars > MAX_ALIAS_CHARS:
        message = (
            f"aliases expand this document by more than {MAX_ALIAS_CHARS} characters of "
            f"text (this alias repeats {size[1]}); at most {MAX_ALIAS_CHARS} are accepted"
        )
        scan.issue(event, path, message, fatal=True)
    _finish_child(scan, size, None)


def _check_alias_ratio(scan: _Scan) -> None:
    limit = ALIAS_FACTOR * scan.written
    if scan.first_alias is not None and not scan.stopped and scan.expanded > limit:
        message = (
            f"aliases add {scan.expanded} nodes to the {scan.written} written; at most "
            f"{ALIAS_FACTOR}x the written nodes are accepted"
        )
        scan.issue(scan.first_alias, (), message)


def _finish_child(scan: _Scan, size: tuple[int, int], key: str | None) -> None:
    """A node of ``size`` (nodes, characters; aliases expanded) is complete: count it in
    its parent."""
    if not scan.frames:
        return
    parent = scan.frames[-1]
    parent.size += size[0]
    parent.chars += size[1]
    if parent.is_mapping and parent.expects_key:
        parent.key = key
    parent.children += 1


def _refuse(file: Path, where: tuple[int, int], message: str) -> Any:
    raise ManifestError(file, [Issue(file, where[0], where[1], "", message)])


def _too_big(size: int) -> str:
    return (
        f"the file is {size} bytes; files of at most {MAX_FILE_BYTES} bytes "
        f"({MAX_FILE_BYTES // (1 << 20)} MiB) are accepted"
    )


def _position_of_byte(data: bytes, offset: int) -> tuple[int, int]:
    line_start = data.rfind(b"\n", 0, offset) + 1
    column = len(data[line_start:offset].decode("utf-8", errors="replace")) + 1
    return data.count(b"\n", 0, offset) + 1, column


def _position_of_char(text: str, offset: int) -> tuple[int, int]:
    return text.count("\n", 0, offset) + 1, offset - (text.rfind("\n", 0, offset) + 1) + 1
