"""Drift guard: the committed generated tree equals a fresh `just schema-export`."""

from __future__ import annotations

import shutil
from pathlib import Path

from openral_codegen import check, export

from tests.conftest import REPO

COPIED = ("schema", "robots", "generated", "docs", "pyproject.toml")


def _copy_repo(target: Path) -> Path:
    for name in COPIED:
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, target / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(source, target / name)
    return target


def test_committed_generated_tree_is_current() -> None:
    problems = check(REPO)
    assert not problems, "run `just schema-export`:\n" + "\n".join(problems)


def test_editing_a_schema_description_without_regenerating_is_detected(tmp_path: Path) -> None:
    root = _copy_repo(tmp_path)
    schema = root / "schema" / "robot.schema.json"
    text = schema.read_text()
    edited = text.replace("Human-readable name shown in tables and docs.", "Name for people.")
    assert edited != text
    schema.write_text(edited)
    problems = check(root)
    assert "stale or edited: generated/openral_generated/models/robot_schema.py" in problems
    assert "stale or edited: docs/reference/robot.md" in problems


def test_export_is_idempotent_and_removes_orphans(tmp_path: Path) -> None:
    root = _copy_repo(tmp_path)
    orphan = root / "generated" / "openral_generated" / "tables" / "gone_robot.json"
    orphan.write_text("{}")
    hand_edit = root / "generated" / "openral_generated" / "tables" / "franka_panda.json"
    hand_edit.write_text(hand_edit.read_text().replace('"robot"', '"robot" ', 1))
    changed = export(root)
    assert changed == [
        "generated/openral_generated/tables/franka_panda.json",
        "generated/openral_generated/tables/gone_robot.json",
    ]
    assert not orphan.exists()
    assert export(root) == []
    assert check(root) == []
