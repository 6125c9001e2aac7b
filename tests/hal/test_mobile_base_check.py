"""Tests for the mobile-base checks of model_check.py (and mobile_base.py): `openral robot
check` refuses a base whose model does not have the mount body, the drive's joint layout
or its velocity actuators, at the manifest's field; a scene refuses it before composing."""

from __future__ import annotations

import pytest
from openral_core import ManifestError, load_robot, load_scene, open_robot
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import check_robot, compile_robot_model
from openral_sim.native_scene import NativeScene

from tests.conftest import ROBOTS, ManifestWriter

MOBILE = ROBOTS / "panda_mobile" / "robot.yaml"


def _failures(write_manifest: ManifestWriter, *edits: tuple[str, str]) -> list[tuple[str, str]]:
    robot = load_robot(write_manifest(*edits, base=MOBILE, folder="panda_mobile"))
    model = compile_robot_model(robot, robot_model_file(robot))
    return [(row.field, row.actual) for row in check_robot(robot, model) if not row.ok]


def test_panda_mobile_passes_every_check(write_manifest: ManifestWriter) -> None:
    assert _failures(write_manifest) == []


@pytest.mark.parametrize(
    ("edit", "failure"),
    [
        (
            ("mount_body: support", "mount_body: saddle"),
            ("mobile_base.mount_body", "not in the model"),
        ),
        (
            ("mount_body: support", "mount_body: world"),
            ("mobile_base.mount_body", "a body the base does not carry"),
        ),
        (
            ("site: base_lidar_site", "site: center"),
            ("sensors[2].site", "a site of that name already"),
        ),
        (
            ("x: joint_mobile_forward", "x: joint_mobile_yaw"),
            ("mobile_base.joints.x", "a hinge there"),
        ),
        (
            ("yaw: joint_mobile_yaw}", "yaw: joint_torso_height}"),
            ("mobile_base.joints.yaw", "a slide there"),
        ),
        (
            ("yaw: joint_mobile_yaw}", "yaw: joint1}"),
            ("mobile_base.joints.yaw", "no such joint"),
        ),
        (
            ("yaw: actuator_mobile_yaw}", "yaw: actuator_mobile_side}"),
            ("mobile_base.actuators.yaw", "it drives another joint"),
        ),
        (
            ("x: joint_mobile_forward", "x: joint_torso_height"),
            ("mobile_base.joints", "not all on one child body of the world"),
        ),
        (
            (
                "mjcf_uri: pkg:robosuite/robosuite/models/assets/bases/omron_mobile_base.xml",
                "mjcf_uri: pkg:robosuite/robosuite/models/assets/bases/none.xml",
            ),
            ("mobile_base.mjcf_uri", "ships no file"),
        ),
    ],
    ids=[
        "mount-body",
        "mount-on-the-world",
        "lidar-site-taken",
        "x-not-slide",
        "yaw-not-hinge",
        "yaw-missing",
        "actuator-drives-another-joint",
        "joints-on-two-bodies",
        "base-model-missing",
    ],
)
def test_a_base_that_disagrees_with_its_model_fails_at_its_field(
    write_manifest: ManifestWriter, edit: tuple[str, str], failure: tuple[str, str]
) -> None:
    failures = _failures(write_manifest, edit)
    field, fragment = failure  # the first failure; an actuator of the old joint may follow
    assert failures[0][0] == field and fragment in failures[0][1], failures
    assert all(f.startswith(field.split(".")[0]) for f, _ in failures)


def test_a_lidar_mount_body_must_be_in_the_arm_or_the_base(write_manifest: ManifestWriter) -> None:
    failures = _failures(
        write_manifest,
        (
            "    mount_body: base\n    mount_position_m: [0.17",
            "    mount_body: mast\n    mount_position_m: [0.17",
        ),
    )
    assert failures == [("sensors[2].mount_body", "not in the model")]


def test_a_scene_refuses_a_base_that_disagrees_before_composing(
    write_manifest: ManifestWriter,
) -> None:
    path = write_manifest(
        ("x: joint_mobile_forward", "x: joint_mobile_yaw"), base=MOBILE, folder="panda_mobile"
    )
    scene = load_scene(ROBOTS / "panda_mobile" / "scenes" / "room.yaml")
    with pytest.raises(ManifestError) as error:
        NativeScene(scene, open_robot(path), render_observations=False)
    issue = error.value.issues[0]
    assert (issue.file, issue.line, issue.field) == (path, 14, "mobile_base.joints.x")
    assert "the model has a hinge there" in issue.message


def test_the_drive_layout_is_read_from_the_compiled_base() -> None:
    from openral_core.tables import mobile_base_wiring
    from openral_mujoco.mobile_base import base_model_file, compile_base_model, drive_geometry

    robot = load_robot(MOBILE)
    wiring = mobile_base_wiring(robot)
    assert wiring is not None
    geometry = drive_geometry(compile_base_model(robot, base_model_file(robot)), wiring)
    assert geometry.kv.tolist() == [1000.0, 1000.0, 1500.0]
    assert geometry.friction.tolist() == [250.0, 250.0, 250.0]
    assert geometry.slides.tolist() == [[1.0, 0.0], [0.0, 1.0]] and geometry.yaw_sign == 1.0
    assert geometry.anchor.tolist() == pytest.approx([-0.21, 0.0])
    assert geometry.root_offset.tolist() == pytest.approx([0.21, 0.0, 0.0])  # body `base`
