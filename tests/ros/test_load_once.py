"""Load once, pass down: the manifest node and ``openral deploy sim`` read the scene file and
the robot's manifest once; a ``manifest_path`` runs as given; a scene for another robot and
stale generated tables are one line each."""

from __future__ import annotations

import re
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from openral_bridge.topics import ACTION_SPEC, JOINT_STATES
from openral_cli.main import app, run
from openral_nodes.manifest_node import ManifestLifecycleNode
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.lifecycle import TransitionCallbackReturn
from sensor_msgs.msg import JointState
from typer.testing import CliRunner

from tests.conftest import FRANKA, ROBOTS
from tests.parse_count import count_parses, stale_franka_table
from tests.ros.ros_helpers import DOMAIN_ID, FRANKA_SCENE, Probe

SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE
JOINT7 = "name: panda_joint7, sim_joint_name: joint7"


@pytest.fixture
def spinner(ros_context: Context) -> Iterator[Spinner]:
    with Spinner(ros_context) as spinner:
        yield spinner


def franka_copy(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    """franka_panda's folder copied outside the repository, its manifest edited."""
    manifest = tmp_path / "franka_panda" / "robot.yaml"
    shutil.copytree(FRANKA.parent, manifest.parent)
    text = manifest.read_text()
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    manifest.write_text(text)
    return manifest


def configured(context: Context, **parameters: object) -> ManifestLifecycleNode:
    defaults = {"sim_env_yaml": str(FRANKA_SCENE), "viewer_enabled": False}
    return ManifestLifecycleNode(context=context, parameter_overrides={**defaults, **parameters})


def test_a_manifest_path_runs_as_given_not_the_repository_manifest(
    ros_context: Context, spinner: Spinner, tmp_path: Path
) -> None:
    manifest = franka_copy(
        tmp_path,
        (JOINT7, "name: copied_joint7, sim_joint_name: joint7"),
        ("panda_joint7: 0.785398}", "copied_joint7: 0.785398}"),  # its start pose
        ("display_name: Franka Emika Panda", "display_name: Copied Panda"),
    )
    probe = Probe(ros_context, {ACTION_SPEC: JointState, JOINT_STATES: JointState}, "load_probe")
    node = configured(ros_context, manifest_path=str(manifest))
    spinner.add_node(probe.node)
    spinner.add_node(node)
    try:
        assert spinner.call(node.trigger_configure) == SUCCESS, node.boot_error
        assert spinner.call(node.trigger_activate) == SUCCESS, node.boot_error
        probe.wait_count(ACTION_SPEC, 1)
        probe.wait_count(JOINT_STATES, 1)
        spec, joints = probe.latest(ACTION_SPEC), probe.latest(JOINT_STATES)
        assert "copied_joint7" in spec.name and "panda_joint7" not in spec.name
        assert list(joints.name)[6] == "copied_joint7"
        assert node.hal is not None and node.hal.description.display_name == "Copied Panda"
    finally:
        spinner.call(node.trigger_deactivate)
        spinner.call(node.trigger_cleanup)
        spinner.remove_node(node)
        spinner.remove_node(probe.node)
        node.destroy_node()
        probe.node.destroy_node()


def test_a_scene_for_another_robot_than_the_manifest_is_one_located_line(
    ros_context: Context,
) -> None:
    node = configured(ros_context, manifest_path=str(ROBOTS / "ur5e" / "robot.yaml"))
    try:
        assert node.trigger_configure() == FAILURE
        assert node.hal is None and node.boot_error is not None
        pattern = rf"{re.escape(str(FRANKA_SCENE))}:\d+:\d+: robot_id: the scene is for "
        assert re.fullmatch(pattern + "franka_panda, not ur5e", node.boot_error)
    finally:
        node.destroy_node()


def test_robot_id_and_a_manifest_path_of_another_robot_are_refused(
    ros_context: Context,
) -> None:
    ur5e = ROBOTS / "ur5e" / "robot.yaml"
    node = configured(ros_context, robot_id="franka_panda", manifest_path=str(ur5e))
    try:
        assert node.trigger_configure() == FAILURE
        assert node.boot_error == (
            f"parameter robot_id is franka_panda but manifest_path {ur5e} is ur5e; set one of them"
        )
    finally:
        node.destroy_node()


def test_deploy_sim_reads_its_scene_and_manifest_once(monkeypatch: pytest.MonkeyPatch) -> None:
    parses = count_parses(monkeypatch)
    args = ["deploy", "sim", "--config", str(FRANKA_SCENE), "--no-viewer", "--duration", "0"]
    result = CliRunner().invoke(app, [*args, "--domain-id", str(DOMAIN_ID)])
    assert result.exit_code == 0, result.output
    assert "clean shutdown" in result.output
    assert parses == {FRANKA_SCENE.resolve(): 1, FRANKA.resolve(): 1}


def test_stale_tables_end_deploy_sim_with_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    stale_franka_table(tmp_path, monkeypatch)
    args = ["deploy", "sim", "--config", str(FRANKA_SCENE), "--no-viewer", "--duration", "0"]
    monkeypatch.setattr(sys, "argv", ["openral", *args, "--domain-id", str(DOMAIN_ID)])
    with pytest.raises(SystemExit) as stop:
        run()
    assert stop.value.code == 1
    assert capsys.readouterr().err == (
        "error: configure failed: generated/openral_generated/tables/franka_panda.json: stale: "
        "made from an earlier robots/franka_panda/robot.yaml; run `just schema-export`\n"
    )
