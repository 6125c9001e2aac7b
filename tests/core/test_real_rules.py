"""Tests for real_rules.py and real_wiring.py: the real section's rules, each on its own
violation, located in the file; and the motor table derived from it."""

from __future__ import annotations

import pytest
from openral_core import ManifestError, load_robot
from openral_core.tables import RobotTables, robot_tables

from tests.conftest import REPO, ManifestWriter

SO101 = REPO / "robots" / "so101" / "robot.yaml"


def _findings(path: object) -> dict[str, str]:
    with pytest.raises(ManifestError) as info:
        load_robot(path)  # type: ignore[arg-type]
    return {issue.field: issue.message for issue in info.value.issues}


@pytest.mark.parametrize(
    ("edit", "field", "fragment"),
    [
        (
            ("      - {joint: elbow_flex, id: 3}\n", ""),
            "real.feetech.motors",
            "no motor for joint(s) elbow_flex",
        ),
        (
            ("{joint: elbow_flex, id: 3}", "{joint: elbow, id: 3}"),
            "real.feetech.motors[2].joint",
            "'elbow' is not a joint of this robot",
        ),
        (
            ("{joint: elbow_flex, id: 3}", "{joint: shoulder_pan, id: 3}"),
            "real.feetech.motors[2].joint",
            "joint 'shoulder_pan' already has motor 1 (motors[0])",
        ),
        (
            ("{joint: gripper, id: 6}", "{joint: gripper, id: 2}"),
            "real.feetech.motors[5].id",
            "id 2 is already the id of motors[1] (shoulder_lift)",
        ),
        (
            ("position_limits: [-1.69, 1.69]", "position_limits: [-3.2, 3.2]"),
            "real.feetech.motors[2].joint",
            "more than one turn of the servo",
        ),
        (
            ("      gripper: {Max_Torque_Limit", "      claw: {Max_Torque_Limit"),
            "real.feetech.joint_settings.claw",
            "'claw' is not a joint of this robot",
        ),
        (("    protocol: 0\n", "    protocol: 1\n"), "real.feetech.protocol", "no Sync Read"),
    ],
)
def test_each_real_rule_fails_on_its_own_violation(
    write_manifest: ManifestWriter, edit: tuple[str, str], field: str, fragment: str
) -> None:
    findings = _findings(write_manifest(edit, base=SO101))
    assert fragment in findings.pop(field)
    # a motor moved off its joint leaves that joint without one, said as well
    assert findings in (
        {},
        {
            "real.feetech.motors": "no motor for joint(s) elbow_flex; every "
            "joint needs exactly one motor"
        },
    )


def test_a_feetech_driver_without_its_bus_is_refused(write_manifest: ManifestWriter) -> None:
    text = SO101.read_text()
    without_bus = text[: text.index("  feetech:\n")]
    findings = _findings(write_manifest(base=SO101, text=without_bus))
    assert list(findings) == ["real.driver"]
    assert "needs its bus" in findings["real.driver"]


def test_a_prismatic_joint_cannot_be_a_servo(write_manifest: ManifestWriter) -> None:
    edit = ("{name: elbow_flex, type: revolute", "{name: elbow_flex, type: prismatic")
    findings = _findings(write_manifest(edit, base=SO101))
    assert "drives a revolute joint" in findings["real.feetech.motors[2].joint"]


def test_the_error_names_file_line_and_column(write_manifest: ManifestWriter) -> None:
    path = write_manifest(("{joint: gripper, id: 6}", "{joint: gripper, id: 1}"), base=SO101)
    with pytest.raises(ManifestError) as info:
        load_robot(path)
    line = next(
        i for i, text in enumerate(path.read_text().splitlines(), 1) if "gripper, id: 1" in text
    )
    assert f"{path}:{line}:" in str(info.value)


def test_the_motor_table_follows_manifest_order_and_merges_settings() -> None:
    tables = robot_tables(load_robot(SO101))
    assert tables.real is not None and tables.real.feetech is not None
    bus = tables.real.feetech
    assert bus.ids == (1, 2, 3, 4, 5, 6)
    assert [m.joint for m in bus.motors] == [
        "shoulder_pan",
        "shoulder_lift",
        "elbow_flex",
        "wrist_flex",
        "wrist_roll",
        "gripper",
    ]
    assert bus.motors[0].settings["P_Coefficient"] == 16
    assert "Max_Torque_Limit" not in bus.motors[0].settings
    assert bus.motors[5].settings["Max_Torque_Limit"] == 500
    assert bus.motors[5].settings["P_Coefficient"] == 16
    assert (bus.model_number, bus.resolution, bus.baud_rate) == (777, 4096, 1_000_000)
    assert bus.registers["Present_Position"] == (56, 2)
    assert tables.real.control_period_s == pytest.approx(0.01)
    assert RobotTables.from_json(tables.to_json()) == tables


def test_a_robot_without_a_real_section_has_no_real_table() -> None:
    tables = robot_tables(load_robot(REPO / "robots" / "ur5e" / "robot.yaml"))
    assert tables.real is None
