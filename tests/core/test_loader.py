"""Tests for loader.py: the one load path and its error reports."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from openral_core import ManifestError, load_robot, load_scene
from openral_core.models import NativeAssets

from tests.conftest import FRANKA, ManifestWriter

LOCATED = re.compile(
    r"^(?P<file>.+\.yaml):(?P<line>\d+):(?P<col>\d+): (?P<field>\S+): (?P<msg>.+)$"
)


def _issues(path: object) -> list[re.Match[str]]:
    with pytest.raises(ManifestError) as info:
        load_robot(path)  # type: ignore[arg-type]
    lines = [issue.format() for issue in info.value.issues]
    matches = [LOCATED.match(line) for line in lines]
    assert all(matches), lines
    return [m for m in matches if m]


def test_franka_manifest_loads() -> None:
    robot = load_robot(FRANKA)
    assert robot.name == "franka_panda"
    assert robot.sim is not None and robot.sim.grippers[0].qpos_scale == 0.08


@pytest.mark.parametrize(
    ("edit", "field", "line", "fragment"),
    [
        (("base: fixed", "base: fixed\ncolour: red"), "colour", 7, "unknown field 'colour'"),
        (("base: fixed", "base: fixed\nbase: mobile"), "base", 7, "also defined on line 6"),
        (("{joint: jaw,", "{joint: claw,"), "sim.grippers[0].joint", 20, "'claw' is not a joint"),
        (
            ("qpos_scale: 0.1", "qpos_scale: wide"),
            "sim.grippers[0].qpos_scale",
            20,
            "expected a number, got a string 'wide'",
        ),
        (
            ("observation.images.camera1", "observation.imgs.camera1"),
            "sensors[0].vla_feature_key",
            12,
            "does not match the required form",
        ),
    ],
    ids=["unknown-key", "duplicate-key", "gripper-not-a-joint", "string-for-number", "bad-vla-key"],
)
def test_bad_manifest_reports_file_line_column_and_field(
    write_manifest: ManifestWriter, edit: tuple[str, str], field: str, line: int, fragment: str
) -> None:
    path = write_manifest(edit)
    (match,) = _issues(path)
    assert match["file"] == str(path)
    assert (match["field"], int(match["line"])) == (field, line)
    assert int(match["col"]) >= 1
    assert fragment in match["msg"]


def test_every_problem_of_a_file_is_reported_at_once(write_manifest: ManifestWriter) -> None:
    path = write_manifest(
        ("display_name: Mock arm", "display_name: 7"),
        ("velocity_limit: 3.0", "velocity_limit: -3.0"),
        ("width: 32", "width: 32.0"),
    )
    fields = {m["field"] for m in _issues(path)}
    assert fields == {"display_name", "joints[1].velocity_limit", "sensors[2].width"}


def test_missing_required_field_names_the_parent_and_the_field(
    write_manifest: ManifestWriter,
) -> None:
    path = write_manifest((", effort_limit: 10.0", ""))
    (match,) = _issues(path)
    assert match["field"] == "joints[1]"
    assert "missing required field 'effort_limit'" in match["msg"]


def test_variant_errors_explain_the_discriminator(write_manifest: ManifestWriter) -> None:
    path = write_manifest(
        ("site: lidar_site, ", ""), ("kind: rgb, width: 64", "kind: rgb, site: s, width: 64")
    )
    messages = {m["field"]: m["msg"] for m in _issues(path)}
    assert messages["sensors[3]"] == "missing required field 'site' (because kind is 'lidar')"
    assert messages["sensors[0].site"] == (
        "unknown field 'site'; expected one of: camera, device, fovy_deg, frame_id, height, "
        "kind, mount_axis, mount_body, mount_position_m, name, rate_hz, robosuite_camera, "
        "vla_feature_key, width (because kind is 'rgb')"
    )


def test_name_must_equal_folder(write_manifest: ManifestWriter) -> None:
    path = write_manifest(folder="another_arm")
    (match,) = _issues(path)
    assert match["field"] == "name" and "must equal the folder name 'another_arm'" in match["msg"]
    assert load_robot(path, check_folder_name=False).name == "mock_arm"


def test_scene_file_errors_are_located(tmp_path: object) -> None:
    from pathlib import Path

    file = Path(str(tmp_path)) / "scene.yaml"
    file.write_text(
        'schema_version: "0.1"\nscene:\n  id: tabletop\n  backend: unreal\n'
        "  observation: {width: 64, height: 64}\n  cameras: [agentview, agentview]\n"
    )
    with pytest.raises(ManifestError) as info:
        load_scene(file)
    found = {issue.field: issue.message for issue in info.value.issues}
    assert found["scene.backend"] == "expected one of native, robosuite, got a string 'unreal'"
    assert found["scene.cameras"] == "items must be unique"


def test_valid_scene_loads_with_defaults(tmp_path: object) -> None:
    from pathlib import Path

    file = Path(str(tmp_path)) / "scene.yaml"
    file.write_text(
        'schema_version: "0.1"\nrobot_id: franka_panda\nscene:\n  id: tabletop\n  backend: native\n'
        "  observation: {width: 64, height: 64}\n  cameras: [agentview]\n"
    )
    scene = load_scene(file)
    assert scene.seed == 0 and scene.scene.assets == "tabletop" and scene.base_pose is None


def _scene_file(tmp_path: Path, backend: str, assets: str | None) -> Path:
    file = tmp_path / "scene.yaml"
    line = f"  assets: {assets}\n" if assets is not None else ""
    file.write_text(
        'schema_version: "0.1"\nrobot_id: franka_panda\nscene:\n  id: lift\n'
        f"  backend: {backend}\n{line}  observation: {{width: 64, height: 64}}\n"
        "  cameras: [agentview]\n"
    )
    return file


@pytest.mark.parametrize(
    ("backend", "assets", "expected"),
    [
        ("native", None, NativeAssets.tabletop),
        ("native", "floor", NativeAssets.floor),
        ("robosuite", "PickPlaceCan", "PickPlaceCan"),
    ],
)
def test_scene_assets_are_the_layout_enum_or_an_environment_name(
    tmp_path: Path, backend: str, assets: str | None, expected: str
) -> None:
    loaded = load_scene(_scene_file(tmp_path, backend, assets)).scene.assets
    assert loaded == expected
    assert isinstance(loaded, NativeAssets) == (backend == "native")


@pytest.mark.parametrize(
    ("backend", "assets", "expected"),
    [
        ("native", "Lift", "expected one of tabletop, floor, got a string 'Lift'"),
        ("native", "kitchen", "expected one of tabletop, floor, got a string 'kitchen'"),
        ("robosuite", "tabletop", "'tabletop' does not match the required form ^[A-Z]"),
        ("robosuite", "lift", "'lift' does not match the required form ^[A-Z]"),
    ],
)
def test_scene_assets_are_checked_against_the_backend(
    tmp_path: Path, backend: str, assets: str, expected: str
) -> None:
    file = _scene_file(tmp_path, backend, assets)
    with pytest.raises(ManifestError) as info:
        load_scene(file)
    (issue,) = info.value.issues  # the precise rule only, not also "no allowed form"
    assert (issue.line, issue.column, issue.field) == (6, 3, "scene.assets")
    assert issue.message.startswith(expected)
    assert issue.message.endswith(f"(because backend is {backend!r})")


def test_unknown_discriminator_lists_the_allowed_values(write_manifest: ManifestWriter) -> None:
    path = write_manifest(("name: tof, kind: depth", "name: tof, kind: sonar"))
    (match,) = _issues(path)
    assert match["field"] == "sensors[2].kind"
    assert match["msg"] == (
        "expected one of depth, force_torque, imu, lidar, pose, rgb, got a string 'sonar'"
    )


def test_continuous_joint_with_limits_is_rejected(write_manifest: ManifestWriter) -> None:
    path = write_manifest(("type: continuous,", "type: continuous, position_limits: [-1.0, 1.0],"))
    (match,) = _issues(path)
    assert match["field"] == "joints[1].position_limits"
    assert "unknown field 'position_limits'" in match["msg"]
    assert match["msg"].endswith("(because type is 'continuous')")
