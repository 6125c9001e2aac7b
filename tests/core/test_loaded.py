"""Tests for loaded.py: generated tables as the runtime input, the stale check and the
in-memory fallback."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import pytest
from openral_core import (
    RobotDescription,
    StaleTables,
    load_robot,
    loaded_robot,
    open_robot,
    open_robot_by_id,
    robot_ids,
    robot_tables,
)
from openral_core import loaded as loaded_module
from openral_core.loaded import generated_table
from openral_core.paths import generated_dir, robots_dir

from tests.conftest import FRANKA, REPO, ROBOTS

LOGGER = "openral_core.loaded"
TABLE = "generated/openral_generated/tables/franka_panda.json"


@pytest.fixture
def repo_copy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of franka_panda's folder and generated table; the resolver points at it."""
    shutil.copytree(ROBOTS / "franka_panda", tmp_path / "robots" / "franka_panda")
    (tmp_path / TABLE).parent.mkdir(parents=True)
    shutil.copy2(REPO / TABLE, tmp_path / TABLE)
    monkeypatch.setattr(loaded_module, "robots_dir", lambda: tmp_path / "robots")
    monkeypatch.setattr(loaded_module, "generated_dir", lambda: tmp_path / "generated")
    return tmp_path


def _edit(file: Path, old: str, new: str) -> None:
    text = file.read_text()
    assert old in text, f"edit target {old!r} not found"
    file.write_text(text.replace(old, new))


@pytest.mark.parametrize("robot_id", robot_ids())
def test_generated_tables_are_read_and_equal_the_computed_ones(
    robot_id: str, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    manifest = robots_dir() / robot_id / "robot.yaml"
    assert generated_table(manifest, robot_id) == (
        generated_dir() / "openral_generated" / "tables" / f"{robot_id}.json"
    )
    robot = open_robot_by_id(robot_id)
    assert robot.name == robot_id and robot.folder == manifest.parent
    assert robot.tables == robot_tables(load_robot(manifest))
    assert robot.tables.manifest == f"robots/{robot_id}/robot.yaml"
    assert not [r for r in caplog.records if r.name == LOGGER]


def test_robot_outside_the_repo_gets_in_memory_tables_logged_once(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    shutil.copytree(ROBOTS / "franka_panda", tmp_path / "franka_panda")
    manifest = tmp_path / "franka_panda" / "robot.yaml"
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    first, second = open_robot(manifest), open_robot(manifest)
    assert first.folder == manifest.parent
    assert first.tables == second.tables == robot_tables(first.description)
    assert first.tables.manifest == str(manifest.resolve())
    assert first.tables.manifest_sha256 == open_robot(FRANKA).tables.manifest_sha256
    records = [r for r in caplog.records if r.name == LOGGER]
    assert len(records) == 1 and records[0].levelno == logging.DEBUG
    assert "computed them in memory" in records[0].getMessage()
    assert str(manifest.resolve()) in records[0].getMessage()


def test_current_table_is_read_from_the_generated_folder(
    repo_copy: Path, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    table = repo_copy / TABLE
    _edit(table, '"joint1"', '"read_from_the_file"')  # proves the file, not a recomputation
    robot = open_robot(repo_copy / "robots" / "franka_panda" / "robot.yaml")
    assert robot.tables.joint_name_map["panda_joint1"] == "read_from_the_file"
    assert not [r for r in caplog.records if r.name == LOGGER]


def test_changed_meaning_makes_the_table_stale(repo_copy: Path) -> None:
    manifest = repo_copy / "robots" / "franka_panda" / "robot.yaml"
    _edit(manifest, "velocity_limit: 0.2,", "velocity_limit: 0.3,")
    with pytest.raises(StaleTables) as raised:
        open_robot(manifest)
    assert str(raised.value) == (
        f"{TABLE}: stale: made from an earlier robots/franka_panda/robot.yaml; "
        "run `just schema-export`"
    )


def test_comments_and_formatting_keep_the_table_current(repo_copy: Path) -> None:
    manifest = repo_copy / "robots" / "franka_panda" / "robot.yaml"
    _edit(manifest, "display_name: Franka Emika Panda", "display_name: 'Franka Emika Panda'  # hi")
    _edit(manifest, "velocity_limit: 0.2,", "velocity_limit: 0.20,")
    _edit(manifest, "base: fixed\n", "\n# a comment\nbase:   fixed\n")
    robot = open_robot(manifest)
    assert robot.tables == robot_tables(load_robot(FRANKA))


def test_unreadable_table_is_reported_in_one_line(repo_copy: Path) -> None:
    (repo_copy / TABLE).write_text('{"robot": "franka_panda"}\n')
    with pytest.raises(StaleTables) as raised:
        open_robot(repo_copy / "robots" / "franka_panda" / "robot.yaml")
    message = str(raised.value)
    assert message.startswith(f"{TABLE}: unreadable (KeyError: ")
    assert message.endswith("; run `just schema-export`") and "\n" not in message


def test_repo_robot_without_a_table_gets_in_memory_tables(
    repo_copy: Path, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    (repo_copy / TABLE).unlink()  # as right after `openral robot scaffold`
    robot = open_robot(repo_copy / "robots" / "franka_panda" / "robot.yaml")
    assert robot.tables.hal_wiring == robot_tables(load_robot(FRANKA)).hal_wiring
    assert len([r for r in caplog.records if r.name == LOGGER]) == 1


def test_loaded_robot_of_a_model_built_in_code_defaults_to_the_robots_folder() -> None:
    loaded = load_robot(FRANKA)
    built = RobotDescription.model_validate(loaded.model_dump(exclude_none=True))
    robot = loaded_robot(built)
    assert robot.folder == robots_dir() / "franka_panda"
    assert robot.tables.manifest is None
    assert robot.tables.manifest_sha256 == open_robot(FRANKA).tables.manifest_sha256
    assert loaded_robot(loaded, Path("/elsewhere")).folder == Path("/elsewhere")
