"""Tests for tables.py: HAL wiring defaults, VLA slots, joint-name map, JSON round trip."""

from __future__ import annotations

from openral_core import load_robot, manifest_sha256, robot_tables
from openral_core.tables import FREE_JOINT_NDOF, FREE_JOINT_NQPOS, RobotTables

from tests.conftest import MOCK_ARM, ManifestWriter


def test_defaults_follow_joint_order_and_overrides_win() -> None:
    wiring = robot_tables(load_robot(MOCK_ARM)).hal_wiring
    assert wiring is not None
    assert wiring.joint_names == ("shoulder", "wrist_roll", "jaw")
    assert wiring.joint_qpos_addr == {"shoulder": 0, "wrist_roll": 1, "jaw": 3}
    assert wiring.joint_qvel_addr == {"shoulder": 0, "wrist_roll": 1, "jaw": 2}
    assert wiring.actuator_index == {"shoulder": 0, "wrist_roll": 1, "jaw": 2}
    assert (
        wiring.control_mode == "position" and wiring.kp == {} and wiring.settle_steps_default == 1
    )


def test_floating_base_shifts_default_addresses(write_manifest: ManifestWriter) -> None:
    path = write_manifest(("  joint_qpos_addr: {jaw: 3}\n", "  floating_base: true\n"))
    wiring = robot_tables(load_robot(path)).hal_wiring
    assert wiring is not None
    assert list(wiring.joint_qpos_addr.values()) == [FREE_JOINT_NQPOS + i for i in range(3)]
    assert list(wiring.joint_qvel_addr.values()) == [FREE_JOINT_NDOF + i for i in range(3)]
    assert list(wiring.actuator_index.values()) == [0, 1, 2]


def test_gripper_actuator_resolves_from_its_joint_unless_given(
    write_manifest: ManifestWriter,
) -> None:
    (gripper,) = robot_tables(load_robot(MOCK_ARM)).hal_wiring.grippers  # type: ignore[union-attr]
    assert (gripper.actuator_index, gripper.mirror_actuator_index) == (2, 3)
    assert (gripper.read_mode, gripper.write_mode) == ("sum_over_scale", "normalised")
    path = write_manifest(("mirror_actuator_index: 3}", "actuator_index: 9}"))
    (given,) = robot_tables(load_robot(path)).hal_wiring.grippers  # type: ignore[union-attr]
    assert (given.actuator_index, given.mirror_actuator_index) == (9, None)


def test_torque_pd_gains_expand_per_driven_joint(write_manifest: ManifestWriter) -> None:
    control = "  control: {mode: torque_pd, kp: {shoulder: 100.0, wrist_roll: 5.0}, kd: 2.0}\n"
    wiring = robot_tables(
        load_robot(write_manifest(("  grippers:\n", control + "  grippers:\n")))
    ).hal_wiring
    assert wiring is not None and wiring.control_mode == "torque_pd"
    assert wiring.kp == {"shoulder": 100.0, "wrist_roll": 5.0}
    assert wiring.kd == {"shoulder": 2.0, "wrist_roll": 2.0}


def test_vla_slots_use_key_suffix_else_name_in_manifest_order() -> None:
    tables = robot_tables(load_robot(MOCK_ARM))
    assert [(s.sensor, s.slot) for s in tables.vla_slots] == [
        ("overhead", "camera1"),
        ("hand", "hand"),
    ]


def test_joint_name_map_uses_sim_joint_name_else_canonical() -> None:
    tables = robot_tables(load_robot(MOCK_ARM))
    assert tables.joint_name_map == {"shoulder": "shoulder", "wrist_roll": "roll", "jaw": "jaw"}


def test_robot_without_sim_block_has_no_wiring(write_manifest: ManifestWriter) -> None:
    text = MOCK_ARM.read_text().split("sim:\n")[0]
    tables = robot_tables(load_robot(write_manifest(text=text)))
    assert tables.hal_wiring is None and tables.joint_name_map["wrist_roll"] == "roll"


def test_json_round_trip_is_lossless_and_deterministic() -> None:
    tables = robot_tables(load_robot(MOCK_ARM))
    text = tables.to_json()
    assert RobotTables.from_json(text) == tables
    assert tables.manifest is not None and len(tables.manifest_sha256) == 64
    assert RobotTables.from_json(text).to_json() == text


def test_tables_record_their_manifest_and_its_hash(write_manifest: ManifestWriter) -> None:
    tables = robot_tables(load_robot(MOCK_ARM))
    assert tables.manifest == "tests/fixtures/robots/mock_arm/robot.yaml"
    assert tables.manifest_sha256 == manifest_sha256(load_robot(MOCK_ARM))
    outside = write_manifest(("sim:\n", "# a comment\nsim:\n"))
    moved = robot_tables(load_robot(outside))
    assert moved.manifest == str(outside.resolve())
    assert moved.manifest_sha256 == tables.manifest_sha256
    assert robot_tables(load_robot(MOCK_ARM), root=MOCK_ARM.parent).manifest == "robot.yaml"


def test_manifest_hash_ignores_formatting_and_follows_meaning(
    write_manifest: ManifestWriter,
) -> None:
    original = manifest_sha256(load_robot(MOCK_ARM))
    text = MOCK_ARM.read_text()
    reformatted = write_manifest(text="# header comment\n\n" + text.replace(": ", ":   "))
    assert manifest_sha256(load_robot(reformatted)) == original
    changed = write_manifest(("velocity_limit: 2.0,", "velocity_limit: 2.5,"))
    assert manifest_sha256(load_robot(changed)) != original
