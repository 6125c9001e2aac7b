"""Tests for yaml_guard.py: hostile files refused with one located line, cheaply."""

from __future__ import annotations

import time
import tracemalloc
from pathlib import Path

import pytest
from openral_core.errors import ManifestError
from openral_core.loader import load_robot
from openral_core.registry import manifest_path
from openral_core.yaml_guard import (
    ALIAS_FACTOR,
    MAX_ALIAS_CHARS,
    MAX_ALIAS_NODES,
    MAX_DEPTH,
    MAX_FILE_BYTES,
    MAX_NODES,
)
from openral_core.yaml_source import load_located


def _refusal(tmp_path: Path, content: str | bytes) -> list[str]:
    """The formatted issues ``load_located`` raises for ``content`` (fails if it loads)."""
    file = tmp_path / "doc.yaml"
    if isinstance(content, bytes):
        file.write_bytes(content)
    else:
        file.write_text(content, encoding="utf-8")
    with pytest.raises(ManifestError) as info:
        load_located(file)
    return [issue.format().replace(f"{file}:", "") for issue in info.value.issues]


def alias_bomb(levels: int) -> str:
    """A "billion laughs" document: ten strings, then ``levels`` lists of ten aliases each."""
    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for level in range(1, levels + 1):
        aliases = ",".join([f"*a{level - 1}"] * 10)
        lines.append(f"a{level}: &a{level} [{aliases}]")
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("a: b\x00c\n", "1:5: <document>: character U+0000 is not allowed in YAML"),
        ("a: 1\nb: x\x1b\n", "2:5: <document>: character U+001B is not allowed in YAML"),
        (b"a: 1\nb: caf\xe9\n", "2:7: <document>: byte 0xe9 is not UTF-8"),
        ("a: !!python/object:os.system ls\n", "1:4: a: YAML tags"),
        ("a: 1\nb:\n  <<: {x: 1}\n", "3:3: b: merge keys (<<) are not supported"),
        ("a: " + "1" * 4301 + "\n", "1:4: a: an integer of 4301 digits; at most 100"),
        ("a: " + "[" * 1200 + "]" * 1200 + "\n", f"nested deeper than {MAX_DEPTH} levels"),
        ("a: &a [1, *a]\n", "1:11: a[1]: alias *a refers to the node that contains it"),
        ("a: *nope\n", "1:4: a: alias *nope names no anchor defined before it"),
        ("a: 1\n---\nb: 2\n", "2:1: <document>: a second YAML document"),
        ("%YAML 1.1\n---\na: yes\n", "%YAML/%TAG directives are not allowed"),
        ("? [a, b]\n: 1\n", "a key must be a plain string, not a mapping or list"),
        ("x: &k a\n*k : 2\n", "2:1: <document>: an alias cannot be a key"),
    ],
    ids=[
        "nul",
        "escape",
        "latin1",
        "python-tag",
        "merge-key",
        "huge-int",
        "deep-flow",
        "self-alias",
        "undefined-alias",
        "two-documents",
        "yaml-1.1",
        "complex-key",
        "alias-key",
    ],
)
def test_hostile_text_is_refused_with_one_located_line(
    tmp_path: Path, content: str | bytes, expected: str
) -> None:
    (message,) = _refusal(tmp_path, content)
    assert expected in message


def test_deep_block_nesting_is_refused_at_the_level_past_the_limit(tmp_path: Path) -> None:
    text = "".join("  " * i + "k:\n" for i in range(400)) + "  " * 400 + "v: 1\n"
    (message,) = _refusal(tmp_path, text)
    assert message.startswith(f"{MAX_DEPTH + 1}:")
    assert f"nested deeper than {MAX_DEPTH} levels" in message


def test_nesting_at_the_limit_loads(tmp_path: Path) -> None:
    file = tmp_path / "doc.yaml"
    file.write_text("a: " + "[" * (MAX_DEPTH - 1) + "1" + "]" * (MAX_DEPTH - 1) + "\n")
    assert load_located(file).data["a"] is not None


@pytest.mark.parametrize("levels", [6, 7, 9])
def test_alias_bomb_is_refused_fast_and_small(tmp_path: Path, levels: int) -> None:
    file = tmp_path / "bomb.yaml"
    file.write_text(alias_bomb(levels))
    tracemalloc.start()
    started = time.perf_counter()
    with pytest.raises(ManifestError) as info:
        load_located(file)
    elapsed_s = time.perf_counter() - started
    _, peak_bytes = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    (issue,) = info.value.issues
    assert f"aliases expand this document by more than {MAX_ALIAS_NODES} nodes" in issue.message
    # a4 is the first list whose aliases (11,111 nodes each) push the total past the limit
    assert (issue.line, issue.field) == (5, "a4[7]")
    assert elapsed_s < 0.1, f"refusing the bomb took {elapsed_s * 1000:.0f} ms"
    assert peak_bytes < 50e6, f"refusing the bomb allocated {peak_bytes / 1e6:.1f} MB"


def test_aliases_within_the_ratio_load_and_expand(tmp_path: Path) -> None:
    file = tmp_path / "doc.yaml"
    file.write_text("limits: &l [1.0, 2.0]\na: *l\nb: *l\n")
    assert load_located(file).data == {"limits": [1.0, 2.0], "a": [1.0, 2.0], "b": [1.0, 2.0]}


def test_aliases_past_the_ratio_are_refused(tmp_path: Path) -> None:
    many = ", ".join(["*l"] * 40)
    (message,) = _refusal(tmp_path, f"l: &l [1, 2, 3, 4]\nx: [{many}]\n")
    assert f"at most {ALIAS_FACTOR}x the written nodes" in message
    assert message.startswith("2:5:")


def test_file_over_the_size_limit_is_refused_without_parsing(tmp_path: Path) -> None:
    (message,) = _refusal(tmp_path, "a: " + "x" * MAX_FILE_BYTES + "\n")
    assert message.startswith("1:1: <document>: the file is")
    assert f"at most {MAX_FILE_BYTES} bytes" in message


def test_too_many_values_are_refused(tmp_path: Path) -> None:
    (message,) = _refusal(tmp_path, "a: [" + "1," * MAX_NODES + "1]\n")
    assert f"more than {MAX_NODES} values in one file" in message


def test_a_directory_is_not_read(tmp_path: Path) -> None:
    with pytest.raises(ManifestError, match="not a regular file"):
        load_located(tmp_path)


def test_brackets_inside_quotes_and_comments_do_not_count_as_nesting(tmp_path: Path) -> None:
    file = tmp_path / "doc.yaml"
    brackets = "[" * (MAX_DEPTH + 5)
    file.write_text(f"a: '{brackets}'\nb: \"{brackets}\"  # {brackets}\n")
    assert load_located(file).data == {"a": brackets, "b": brackets}


def test_utf8_bom_is_accepted(tmp_path: Path) -> None:
    file = tmp_path / "doc.yaml"
    file.write_bytes("\ufeffa: 1\n".encode())
    assert load_located(file).data == {"a": 1}


LONG = 10 * 1024
"""Length of the anchored string in the long-string alias tests [characters]."""


def long_string_aliases(count: int, written: int = 0) -> str:
    """A manifest-shaped file: one anchored string of :data:`LONG` characters, ``written``
    plain numbers, then ``count`` aliases to the string in a block list."""
    head = f'name: &a "{"x" * LONG}"\nnumbers: [{", ".join(["1"] * written)}]\njoints:\n'
    return head + "  - *a\n" * count


def test_aliases_to_a_long_string_are_refused_at_the_crossing_alias(tmp_path: Path) -> None:
    file = tmp_path / "robot.yaml"
    file.write_text(long_string_aliases(140_000))
    assert 0.9e6 < file.stat().st_size <= MAX_FILE_BYTES
    tracemalloc.start()
    with pytest.raises(ManifestError) as info:
        load_robot(file, check_folder_name=False)
    _, peak_bytes = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    (issue,) = info.value.issues
    crossing = MAX_ALIAS_CHARS // LONG  # index of the first alias past the bound
    assert (issue.line, issue.column, issue.field) == (4 + crossing, 5, f"joints[{crossing}]")
    assert issue.message == (
        f"aliases expand this document by more than {MAX_ALIAS_CHARS} characters of text "
        f"(this alias repeats {LONG}); at most {MAX_ALIAS_CHARS} are accepted"
    )
    assert len(str(info.value).splitlines()) == 1
    assert peak_bytes < 50e6, f"refusing the file allocated {peak_bytes / 1e6:.1f} MB"


def test_long_string_aliases_within_the_node_ratio_are_refused_too(tmp_path: Path) -> None:
    # The fuzzed shape: enough written values that the node ratio allows every alias.
    (message,) = _refusal(tmp_path, long_string_aliases(3_000, written=1_000))
    assert f"more than {MAX_ALIAS_CHARS} characters of text" in message
    assert message.startswith(f"{4 + MAX_ALIAS_CHARS // LONG}:5: joints[")


def test_aliases_count_as_values_written(tmp_path: Path) -> None:
    text = "a: &a x\nb: [" + "*a," * MAX_NODES + "*a]\n"
    (message,) = _refusal(tmp_path, text)
    crossing = MAX_NODES - 5  # the mapping, a, x, b and the list are the 5 written values
    assert message.startswith(f"2:{5 + 3 * crossing}: b[{crossing}]: more than")
    assert f"more than {MAX_NODES} values in one file" in message


def test_aliases_up_to_the_character_bound_load_and_share_one_string(tmp_path: Path) -> None:
    file = tmp_path / "doc.yaml"
    count = MAX_ALIAS_CHARS // LONG
    file.write_text(long_string_aliases(count, written=count // ALIAS_FACTOR))
    joints = load_located(file).data["joints"]
    assert len(joints) == count and joints[0] == "x" * LONG
    assert all(joint is joints[0] for joint in joints)


def test_a_manifest_with_a_few_aliases_loads_as_if_written_out(tmp_path: Path) -> None:
    original = manifest_path("franka_panda")
    text = original.read_text(encoding="utf-8")
    limits = "position_limits: [-2.8973, 2.8973]"
    assert text.count(limits) == 4
    text = text.replace(limits, "position_limits: &wide [-2.8973, 2.8973]", 1)
    text = text.replace(limits, "position_limits: *wide")
    text = text.replace("rate_hz: 10.0", "rate_hz: &camera_hz 10.0", 1)
    text = text.replace("rate_hz: 10.0", "rate_hz: *camera_hz")
    assert text.count("*wide") == 3 and text.count("*camera_hz") == 1
    (tmp_path / "franka_panda").mkdir()
    file = tmp_path / "franka_panda" / "robot.yaml"
    file.write_text(text, encoding="utf-8")
    assert load_robot(file).model_dump() == load_robot(original).model_dump()
