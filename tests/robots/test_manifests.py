"""Every robot folder is data only, valid, and has its generated tables committed."""

from __future__ import annotations

import pytest
from openral_core import load_robot, robot_ids, robot_tables
from openral_core.tables import RobotTables

from tests.conftest import REPO, ROBOTS

IDS = robot_ids(ROBOTS)
REQUIRED_FILES = ("robot.yaml", "README.md")
SCHEMA_LINE = "# yaml-language-server: $schema=../../schema/robot.schema.json"
EXPECTED_ROBOTS = {
    "franka_panda",
    "ur5e",
    "ur10e",
    "aloha",
    "g1",
    "h1",
    "rizon4",
    "so100",
    "so101",
    "openarm",
}


def test_the_ten_robots_are_present() -> None:
    assert set(IDS) >= EXPECTED_ROBOTS, f"missing: {sorted(EXPECTED_ROBOTS - set(IDS))}"


@pytest.mark.parametrize("robot_id", IDS)
def test_robot_folder_layout(robot_id: str) -> None:
    folder = ROBOTS / robot_id
    missing = [name for name in REQUIRED_FILES if not (folder / name).is_file()]
    assert not missing, f"robots/{robot_id} lacks {', '.join(missing)}"
    python = sorted(p.name for p in folder.rglob("*.py"))
    assert not python, f"robots/{robot_id} must be data only; found {python}"
    first_line = (folder / "robot.yaml").read_text().splitlines()[0]
    assert first_line == SCHEMA_LINE, (
        f"robots/{robot_id}/robot.yaml must start with {SCHEMA_LINE!r}"
    )


@pytest.mark.parametrize("robot_id", IDS)
def test_manifest_is_valid_and_its_generated_tables_are_current(robot_id: str) -> None:
    robot = load_robot(ROBOTS / robot_id / "robot.yaml")
    generated = REPO / "generated" / "openral_generated" / "tables" / f"{robot_id}.json"
    assert generated.is_file(), f"{generated} missing; run `just schema-export`"
    assert RobotTables.from_json(generated.read_text()) == robot_tables(robot)


@pytest.mark.parametrize("robot_id", IDS)
def test_manifest_declares_a_sim_model(robot_id: str) -> None:
    robot = load_robot(ROBOTS / robot_id / "robot.yaml")
    assert robot.sim is not None, f"{robot_id} has no sim block"


@pytest.mark.parametrize("robot_id", ["franka_panda", "ur5e", "aloha"])
def test_camera_robots_declare_vla_slots(robot_id: str) -> None:
    slots = robot_tables(load_robot(ROBOTS / robot_id / "robot.yaml")).vla_slots
    assert slots and all(s.slot.startswith("camera") for s in slots)
