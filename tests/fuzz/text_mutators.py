"""Mutations of a file's bytes: what an editor slip, a bad merge or a hostile author makes.

Each mutator takes the file's bytes, a seeded :class:`random.Random` and the bytes of the
other seed files (donors for splicing) and returns new bytes; the same inputs always give
the same output.
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable, Sequence

TextMutator = Callable[[bytes, random.Random, Sequence[bytes]], bytes]

CONTROL = (
    b"\x00",
    b"\x07",
    b"\x1b[31m",
    b"\x7f",
    b"\r",
    b"\t",
    b"\x0b",
    b"\x0c",
    "\u0085".encode(),
    "\u2028".encode(),
    "\u202e".encode(),
    "\ufeff".encode(),
    "\ufffe".encode(),
    "\u200b".encode(),
)
"""Control and format characters: C0, DEL, NEL, line separator, bidi override, BOM, ZWSP."""
NOT_UTF8 = (b"\xff", b"\xc3\x28", b"\xed\xa0\x80", b"\xc0\xaf", b"\xf8\x88\x80\x80\x80", b"\x80")
"""Bytes no UTF-8 decoder accepts: stray bytes, a surrogate, overlong and 5-byte forms."""
SYNTAX = tuple(
    s.encode()
    for s in ("[", "]", "{", "}", '"', "'", ": ", "- ", "#", "|", ">", "? ", "`", "@", ",", "\\")
)
"""Brackets, quotes and YAML indicators."""
HUGE_NUMBERS = tuple(
    s.encode()
    for s in (
        "1e999",
        "-1e999",
        "1e308",
        "5e-324",
        "1e-8",
        "-0.0",
        "0",
        "-1",
        ".inf",
        "-.inf",
        ".nan",
        "0x7fffffffffffffff",
        "0o777",
        "1_000_000",
        "9" * 99,
        "9" * 101,
        "9" * 5000,
        "1" + "0" * 400 + ".0",
        "18446744073709551617",
        "1.7976931348623157e308",
        "NaN",
        "~",
        "null",
    )
)
"""Numbers at and past every limit a float, an int or the reader has."""
_NUMBER = re.compile(rb"(?<![\w.])-?\d+(?:\.\d+)?(?:e-?\d+)?(?![\w.])")
_VALUE = re.compile(rb":[ ]+(?=\S)|- (?=\S)")


def lines_of(data: bytes) -> list[bytes]:
    """The lines of ``data`` with their line ends (at least one, possibly empty, line)."""
    return data.splitlines(keepends=True) or [b""]


def _insert(data: bytes, rng: random.Random, piece: bytes) -> bytes:
    at = rng.randrange(len(data) + 1)
    return data[:at] + piece + data[at:]


def flip_byte(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """XOR one bit of one byte."""
    if not data:
        return b"\x00"
    at = rng.randrange(len(data))
    return data[:at] + bytes([data[at] ^ (1 << rng.randrange(8))]) + data[at + 1 :]


def replace_char(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Overwrite one byte with a printable character or a YAML indicator."""
    if not data:
        return data
    at = rng.randrange(len(data))
    piece = rng.choice([bytes([rng.randrange(0x20, 0x7F)]), rng.choice(SYNTAX)])
    return data[:at] + piece + data[at + 1 :]


def insert_control(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Insert a control or format character somewhere."""
    return _insert(data, rng, rng.choice(CONTROL))


def insert_not_utf8(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Insert bytes that are not UTF-8."""
    return _insert(data, rng, rng.choice(NOT_UTF8))


def insert_syntax(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Insert a bracket, quote or indicator, after a key's colon or at random."""
    piece = rng.choice(SYNTAX)
    spots = [m.end() for m in _VALUE.finditer(data)]
    if spots and rng.random() < 0.6:
        at = rng.choice(spots)
        return data[:at] + piece + data[at:]
    return _insert(data, rng, piece)


def delete_line(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Drop one line."""
    lines = lines_of(data)
    del lines[rng.randrange(len(lines))]
    return b"".join(lines)


def duplicate_line(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Repeat one line right after itself (a duplicate key or list item)."""
    lines = lines_of(data)
    at = rng.randrange(len(lines))
    lines.insert(at, lines[at] if lines[at].endswith(b"\n") else lines[at] + b"\n")
    return b"".join(lines)


def swap_lines(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Exchange two lines."""
    lines = lines_of(data)
    a, b = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[a], lines[b] = lines[b], lines[a]
    return b"".join(lines)


def reindent(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Indent or dedent one line, with spaces or a tab."""
    lines = lines_of(data)
    at = rng.randrange(len(lines))
    line = lines[at]
    choice = rng.randrange(4)
    if choice == 0:
        lines[at] = b" " * rng.choice((1, 2, 4, 40)) + line
    elif choice == 1:
        lines[at] = line[rng.randint(1, 4) :] if line.startswith(b" ") else line
    elif choice == 2:
        lines[at] = b"\t" + line
    else:
        lines[at] = line.lstrip(b" ")
    return b"".join(lines)


def splice_line(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Insert or overwrite a line with a line of another seed file."""
    lines = lines_of(data)
    donor = lines_of(rng.choice(donors)) if donors else lines
    piece = rng.choice(donor)
    piece = piece if piece.endswith(b"\n") else piece + b"\n"
    at = rng.randrange(len(lines))
    if rng.random() < 0.5:
        lines[at] = piece
    else:
        lines.insert(at, piece)
    return b"".join(lines)


def inject_yaml_feature(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Add an anchor and alias, a merge key, a tag, a directive or a second document."""
    lines = lines_of(data)
    at = rng.randrange(len(lines))
    indent = lines[at][: len(lines[at]) - len(lines[at].lstrip(b" "))]
    bomb = b"".join(
        b"l%d: &l%d [*l%d, *l%d, *l%d, *l%d]\n" % (i, i, i - 1, i - 1, i - 1, i - 1)
        for i in range(1, 12)
    )
    pieces = [
        indent + b"fuzz_anchor: &a {x: 1}\n" + indent + b"fuzz_alias: *a\n",
        indent + b"<<: {extra: 1}\n",
        indent + b"fuzz_self: &s [*s]\n",
        indent + b"fuzz_undefined: *nowhere\n",
        indent + b'fuzz_tag: !!python/object/apply:os.system ["true"]\n',
        indent + b"fuzz_tag: !custom 1\n",
        indent + b"? [complex, key]\n" + indent + b": 1\n",
        b"l0: &l0 [x]\n" + bomb,
    ]
    whole = [
        b"%YAML 1.1\n---\n" + data,
        data + b"\n---\nsecond: document\n",
        b"---\n" + data,
        data + b"\n...\n",
        b"\xef\xbb\xbf" + data,
        data.replace(b"\n", b"\r\n"),
    ]
    if rng.random() < 0.35:
        return rng.choice(whole)
    lines.insert(at, rng.choice(pieces))
    return b"".join(lines)


def huge_number(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Replace a number in the text with one at or past a limit."""
    numbers = list(_NUMBER.finditer(data))
    if not numbers:
        return _insert(data, rng, rng.choice(HUGE_NUMBERS))
    match = rng.choice(numbers)
    return data[: match.start()] + rng.choice(HUGE_NUMBERS) + data[match.end() :]


def oversize(data: bytes, rng: random.Random, donors: Sequence[bytes]) -> bytes:
    """Make the file huge, deeply nested, very wide or truncated."""
    choice = rng.randrange(6)
    if choice == 0:
        return data + b"# " + b"x" * ((1 << 20) + 10) + b"\n"
    if choice == 1:
        depth = rng.choice((33, 200, 100_000))
        return data + b"fuzz_deep: " + b"[" * depth + b"]" * depth + b"\n"
    if choice == 2:
        depth = rng.choice((33, 300))
        return (
            data
            + b"".join(b"  " * i + b"k%d:\n" % i for i in range(depth))
            + b"  " * depth
            + b"v: 1\n"
        )
    if choice == 3:
        return data + b"fuzz_wide: [" + b"0, " * 25_000 + b"0]\n"
    if choice == 4:
        return data + b"fuzz_long: " + b"y" * 500_000 + b"\n"
    return data[: rng.randrange(len(data) + 1)]


TEXT_MUTATORS: dict[str, TextMutator] = {
    "flip_byte": flip_byte,
    "replace_char": replace_char,
    "insert_control": insert_control,
    "insert_not_utf8": insert_not_utf8,
    "insert_syntax": insert_syntax,
    "delete_line": delete_line,
    "duplicate_line": duplicate_line,
    "swap_lines": swap_lines,
    "reindent": reindent,
    "splice_line": splice_line,
    "inject_yaml_feature": inject_yaml_feature,
    "huge_number": huge_number,
    "oversize": oversize,
}
"""Every text mutator by name (the name is what a case records)."""
