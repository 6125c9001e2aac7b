"""Drift guard: the committed generated tree equals a fresh `just schema-export`."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from openral_codegen import check, export

from tests.conftest import REPO

FRANKA_TABLE = "generated/openral_generated/tables/franka_panda.json"
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


def test_a_table_with_a_wrong_manifest_hash_is_detected(tmp_path: Path) -> None:
    root = _copy_repo(tmp_path)
    table = root / FRANKA_TABLE
    text = table.read_text()
    table.write_text(text.replace(json.loads(text)["manifest_sha256"], "0" * 64))
    assert check(root) == [f"stale or edited: {FRANKA_TABLE}"]


def test_export_under_another_root_records_the_same_manifest_path(tmp_path: Path) -> None:
    root = _copy_repo(tmp_path)
    manifest = root / "robots" / "franka_panda" / "robot.yaml"
    edited = manifest.read_text().replace("velocity_limit: 0.2,", "velocity_limit: 0.3,")
    manifest.write_text(edited)
    assert FRANKA_TABLE in export(root)
    table = json.loads((root / FRANKA_TABLE).read_text())
    assert table["manifest"] == "robots/franka_panda/robot.yaml"
    committed = json.loads((REPO / FRANKA_TABLE).read_text())
    assert table["manifest_sha256"] != committed["manifest_sha256"]
