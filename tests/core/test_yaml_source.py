"""Tests for yaml_source.py: safe loading with positions."""

from __future__ import annotations

from pathlib import Path

import pytest
from openral_core.errors import ManifestError
from openral_core.yaml_source import format_field, load_located


def _load_error(tmp_path: Path, text: str) -> ManifestError:
    file = tmp_path / "doc.yaml"
    file.write_text(text)
    with pytest.raises(ManifestError) as info:
        load_located(file)
    return info.value


def test_positions_are_one_based_line_and_column(tmp_path: Path) -> None:
    file = tmp_path / "doc.yaml"
    file.write_text("a: 1\nb:\n  - x: 2\n    y: [3, 4]\n")
    doc = load_located(file)
    assert doc.data == {"a": 1, "b": [{"x": 2, "y": [3, 4]}]}
    assert doc.position(("a",)) == (1, 1)
    assert doc.position(("b", 0, "y")) == (4, 5)
    assert doc.position(("b", 0, "y", 1, "missing")) == doc.position(("b", 0, "y", 1))


def test_duplicate_keys_name_both_lines_and_are_all_reported(tmp_path: Path) -> None:
    error = _load_error(tmp_path, "a: 1\nb: {c: 1}\na: 2\nd:\n  - {e: 1, e: 2}\n")
    messages = [issue.format() for issue in error.issues]
    assert len(messages) == 2
    assert messages[0].endswith(
        "doc.yaml:3:1: a: duplicate key 'a': also defined on line 1; each key may appear once"
    )
    assert "d[0].e: duplicate key 'e': also defined on line 5" in messages[1]


@pytest.mark.parametrize("value", [".inf", "-.inf", ".nan"])
def test_non_finite_numbers_are_rejected(tmp_path: Path, value: str) -> None:
    error = _load_error(tmp_path, f"x:\n  y: {value}\n")
    (issue,) = error.issues
    assert (issue.line, issue.field) == (2, "x.y")
    assert "expected a finite number" in issue.message


def test_tags_are_refused_before_anything_is_built(tmp_path: Path) -> None:
    error = _load_error(tmp_path, "a: !python/object:os.system ls\nb: !!str 3\n")
    fields = {issue.field: issue.message for issue in error.issues}
    assert "YAML tags (!python/object:os.system) are not allowed" in fields["a"]
    assert "YAML tags (tag:yaml.org,2002:str) are not allowed" in fields["b"]


def test_dates_are_rejected_where_they_stand(tmp_path: Path) -> None:
    (issue,) = _load_error(tmp_path, "a: 1\nb: 2024-01-01\n").issues
    assert (issue.line, issue.field) == (2, "b")
    assert "unsupported YAML value" in issue.message


def test_syntax_error_is_located(tmp_path: Path) -> None:
    (issue,) = _load_error(tmp_path, "a: [1, 2\nb: 3\n").issues
    assert issue.line >= 1 and "invalid YAML" in issue.message


def test_missing_file_is_reported_not_raised_raw(tmp_path: Path) -> None:
    with pytest.raises(ManifestError, match="cannot read file"):
        load_located(tmp_path / "absent.yaml")


def test_format_field_renders_dots_and_indices() -> None:
    assert format_field(("sim", "grippers", 0, "joint")) == "sim.grippers[0].joint"
    assert format_field(()) == ""


def test_a_file_parsed_again_is_a_copy_and_an_edit_is_parsed_afresh(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from openral_core import yaml_source

    parses: list[Path] = []
    parse = yaml_source._parse
    monkeypatch.setattr(
        yaml_source, "_parse", lambda file, text: parses.append(file) or parse(file, text)
    )
    file = tmp_path / "doc.yaml"
    file.write_text("a: [1, 2]\n")
    first = load_located(file)
    first.data["a"].append(3)  # a caller's change stays in its copy
    second = load_located(file)
    assert second.data == {"a": [1, 2]} and second.position(("a",)) == (1, 1)
    assert len(parses) == 1
    file.write_text("a: [1, 5]\n")  # same size, other text: parsed again
    assert load_located(file).data == {"a": [1, 5]} and len(parses) == 2
    file.write_text("a: [1\n")
    with pytest.raises(ManifestError):
        load_located(file)
    with pytest.raises(ManifestError):  # a failure is not remembered: it fails again
        load_located(file)
    assert len(parses) == 4
