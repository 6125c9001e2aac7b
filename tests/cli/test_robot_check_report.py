"""``openral robot check`` and ``robot list`` point into the file: each mismatch at the
manifest's line and column, a misspelt name with the closest valid ones, a manifest that
does not load counted apart from mismatches; and a scene's unknown camera likewise."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from openral_cli.main import app
from openral_core import ManifestError
from openral_core.errors import did_you_mean
from typer.testing import CliRunner

from tests.conftest import ROBOTS, ManifestWriter

runner = CliRunner()
UR5E = ROBOTS / "ur5e" / "robot.yaml"
WIDE = {"COLUMNS": "250"}


def position(file: Path, text: str, key: str) -> str:
    """``robot.yaml:line:col`` of ``key`` on the one line of ``file`` holding ``text``."""
    (number, row), *others = [
        (n, row) for n, row in enumerate(file.read_text().splitlines(), 1) if text in row
    ]
    assert not others
    return f"{file.name}:{number}:{row.index(key) + 1}"


def test_did_you_mean_names_the_closest_candidates_only() -> None:
    joints = [f"joint{i}" for i in range(1, 8)]
    assert did_you_mean("iiwa_joint_1", joints) == " (did you mean joint1?)"
    assert did_you_mean("joint_3", joints) == " (did you mean joint3?)"
    assert did_you_mean("nmae", ["name", "kind"]) == " (did you mean name?)"
    assert did_you_mean("colour", ["base", "name"]) == ""
    assert did_you_mean("name", ["name"]) == ""


def test_each_mismatch_row_names_its_line_and_column_and_the_closest_name(
    write_manifest: ManifestWriter,
) -> None:
    manifest = write_manifest(
        ("name: wrist_2_joint,", "name: wrist_2_joint, sim_joint_name: wrist_2_jiont,"),
        ("mount_body: wrist_3_link", "mount_body: wrist_3_lnk"),
        base=UR5E,
        folder="ur5e",
    )
    result = runner.invoke(app, ["robot", "check", str(manifest)], env=WIDE)
    assert result.exit_code == 1
    rows = {
        cells[2]: cells[1:6]
        for line in result.stdout.splitlines()
        if "MISMATCH" in line
        for cells in [[cell.strip() for cell in line.split("│")]]
    }
    assert rows == {
        "joints[4].sim_joint_name": [
            position(manifest, "wrist_2_jiont", "sim_joint_name"),
            "joints[4].sim_joint_name",
            "wrist_2_jiont",
            "no such joint in the model (did you mean wrist_2_joint?)",
            "MISMATCH",
        ],
        "sensors[1].mount_body": [
            position(manifest, "wrist_3_lnk", "mount_body"),
            "sensors[1].mount_body",
            "wrist_3_lnk",
            "not in the model (did you mean wrist_3_link?)",
            "MISMATCH",
        ],
    }
    assert result.stderr == "1 of 1 robot(s) do not match their model\n"


def test_a_manifest_that_does_not_load_is_counted_as_not_checked(
    write_manifest: ManifestWriter,
) -> None:
    invalid = write_manifest(("base: fixed", "base: fixed\nnmae: x"), folder="invalid")
    result = runner.invoke(app, ["robot", "check", str(invalid)], env=WIDE)
    assert result.exit_code == 1
    assert result.stderr.splitlines() == [
        f"✗ {invalid}:7:1: nmae: unknown field 'nmae' (did you mean name?); expected one of: "
        "base, display_name, frames, joints, mobile_base, name, real, schema_version, sensors, "
        "sim, trajectory",
        "1 of 1 robot(s) could not be checked",
    ]
    assert re.search(r"│ invalid +│ - +│ - +│ could not be checked +│", result.stdout)


def test_mismatches_and_unloadable_manifests_are_told_apart(
    write_manifest: ManifestWriter,
) -> None:
    invalid = write_manifest(("base: fixed", "base: fixed\nbase: mobile"), folder="invalid")
    mismatch = write_manifest(("keyframe_index: 0", "keyframe_index: 3"), base=UR5E, folder="ur5e")
    result = runner.invoke(app, ["robot", "check", str(invalid), str(mismatch), "so100"])
    assert result.exit_code == 1
    assert result.stderr.splitlines()[-1] == (
        "1 of 3 robot(s) do not match their model; 1 could not be checked"
    )


def test_validate_suggests_the_closest_allowed_key(write_manifest: ManifestWriter) -> None:
    manifest = write_manifest(("base: fixed", "bsae: fixed"), folder="mock_arm")
    result = runner.invoke(app, ["robot", "validate", str(manifest)], env=WIDE)
    assert result.exit_code == 1
    assert f"{manifest}:6:1: bsae: unknown field 'bsae' (did you mean base?);" in result.stderr


def test_list_shows_an_invalid_robot_with_its_located_problem(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import openral_core.registry as registry

    robots = tmp_path / "robots"
    (robots / "ur5e").mkdir(parents=True)
    (robots / "ur5e" / "robot.yaml").write_text(UR5E.read_text())
    (robots / "bad_arm").mkdir()
    bad = robots / "bad_arm" / "robot.yaml"
    bad.write_text(UR5E.read_text().replace("name: ur5e\n", "name: bad_arm\nnmae: x\n"))
    monkeypatch.setattr(registry, "robots_dir", lambda: robots)
    result = runner.invoke(app, ["robot", "list"], env=WIDE)
    assert result.exit_code == 1
    row = next(line for line in result.stdout.splitlines() if "bad_arm" in line)
    assert [cell.strip() for cell in row.split("│")][1:-1] == ["bad_arm (invalid)", *"-----"]
    assert result.stderr == (
        f"✗ {bad}:8:1: nmae: unknown field 'nmae' (did you mean name?); expected one of: "
        "base, display_name, frames, joints, mobile_base, name, real, schema_version, sensors, "
        "sim, trajectory\n"
    )
    assert re.search(r"│ ur5e +│ +6 │", result.stdout)


def test_an_unknown_scene_camera_is_located_with_the_closest_names(tmp_path: Path) -> None:
    from openral_sim.scene import build_sim_env_from_yaml

    text = (ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml").read_text()
    scene = tmp_path / "scene.yaml"
    scene.write_text(text.replace("cameras: [agentview, wrist,", "cameras: [agentview, wirst,"))
    row = next(n for n, line in enumerate(scene.read_text().splitlines(), 1) if "wirst" in line)
    column = scene.read_text().splitlines()[row - 1].index("wirst") + 1
    with pytest.raises(ManifestError) as caught:
        build_sim_env_from_yaml(scene)
    assert str(caught.value) == (
        f"{scene}:{row}:{column}: scene.cameras[1]: 'wirst' is not a camera sensor of robot "
        "'franka_panda' (did you mean wrist?); its camera sensors are: agentview, wrist, "
        "front_depth"
    )


def test_the_deprecated_robosuite_scheme_still_resolves_and_is_reported(tmp_path: Path) -> None:
    folder = tmp_path / "panda_mobile"
    folder.mkdir()
    source = (ROBOTS / "panda_mobile" / "robot.yaml").read_text()
    modern = "pkg:robosuite/robosuite/models/assets/bases/omron_mobile_base.xml"
    assert modern in source  # the repository's own robot uses the one scheme
    manifest = folder / "robot.yaml"
    manifest.write_text(source.replace(modern, "robosuite:bases/omron_mobile_base.xml"))
    result = runner.invoke(app, ["robot", "check", str(manifest)], env=WIDE)
    assert result.exit_code == 0, result.output  # an alias: the same file, every check passes
    where = position(manifest, "robosuite:bases", "mjcf_uri")
    assert (
        f"! {manifest.parent}/{where}: mobile_base.mjcf_uri: 'robosuite:bases/omron_mobile_base"
        f".xml' is deprecated; write '{modern}' (the same file)"
    ) in result.output
    plain = runner.invoke(app, ["robot", "check", str(ROBOTS / "panda_mobile" / "robot.yaml")])
    assert plain.exit_code == 0 and "deprecated" not in plain.output
