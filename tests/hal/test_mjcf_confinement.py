"""A robot's model and every file it loads stay in the robot's folder or its package.

Each test builds a copy of robots/rizon4 (``file:mjcf/rizon4.xml``) in a tmp folder and
changes its manifest or model; refusals must be one line naming the file and the path.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest
from openral_cli.main import app
from openral_mujoco.mjcf_confinement import (
    ALLOW_OUTSIDE_ENV,
    Confinement,
    MjcfConfinementError,
    check_mjcf_files,
)
from openral_mujoco.mjcf_uri import MjcfUriError, locate_mjcf_uri, resolve_mjcf_uri
from typer.testing import CliRunner

from tests.conftest import ROBOTS

RIZON = ROBOTS / "rizon4"
MODEL = (RIZON / "mjcf" / "rizon4.xml").read_text(encoding="utf-8")
URI = "file:mjcf/rizon4.xml"
# A one-triangle-fan tetrahedron: the smallest mesh MuJoCo compiles.
OBJ = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
runner = CliRunner()


def _robot(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    """robots/rizon4 copied to ``tmp_path/robots/rizon4`` with ``edits`` made to its MJCF."""
    folder = tmp_path / "robots" / "rizon4"
    (folder / "mjcf").mkdir(parents=True)
    shutil.copy(RIZON / "robot.yaml", folder / "robot.yaml")
    text = MODEL
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    (folder / "mjcf" / "rizon4.xml").write_text(text, encoding="utf-8")
    return folder


def _asset(xml: str) -> tuple[str, str]:
    return ("<asset>", f"<asset>\n    {xml}")


def _top(xml: str) -> tuple[str, str]:
    return ('<option integrator="implicitfast"/>', f'<option integrator="implicitfast"/>{xml}')


def _set_uri(folder: Path, uri: str) -> None:
    manifest = folder / "robot.yaml"
    text = manifest.read_text(encoding="utf-8")
    manifest.write_text(text.replace(f"mjcf_uri: {URI}", f"mjcf_uri: {uri}"), encoding="utf-8")


def _refusal(folder: Path, uri: str = URI, *, outside: bool = True) -> str:
    with pytest.raises(MjcfUriError) as caught:
        resolve_mjcf_uri(uri, folder)
    message = str(caught.value)
    assert "\n" not in message
    assert str(folder / "robot.yaml") in message
    assert (f"{ALLOW_OUTSIDE_ENV}=1" in message) == outside
    return message


def _check_cli(folder: Path, allowed: bool = False) -> tuple[int, str]:
    env = {"COLUMNS": "400", ALLOW_OUTSIDE_ENV: "1" if allowed else "0"}
    result = runner.invoke(app, ["robot", "check", str(folder)], env=env)
    assert "Traceback" not in result.output
    return result.exit_code, result.output


# --------------------------------------------------------------------------- the URI itself


def test_file_etc_passwd_is_refused(tmp_path: Path) -> None:
    folder = _robot(tmp_path)
    message = _refusal(folder, "file:/etc/passwd")
    assert "resolves to /etc/passwd, outside the robot folder" in message


def test_file_dotdot_leaving_the_folder_is_refused(tmp_path: Path) -> None:
    folder = _robot(tmp_path)
    (tmp_path / "x.xml").write_text(MODEL, encoding="utf-8")
    message = _refusal(folder, "file:../../x.xml")
    assert f"resolves to {tmp_path / 'x.xml'}, outside the robot folder {folder}" in message


def test_symlink_inside_the_folder_pointing_outside_is_refused(tmp_path: Path) -> None:
    folder = _robot(tmp_path)
    outside = tmp_path / "elsewhere.xml"
    outside.write_text(MODEL, encoding="utf-8")
    (folder / "mjcf" / "link.xml").symlink_to(outside)
    message = _refusal(folder, "file:mjcf/link.xml")
    assert f"resolves to {outside}" in message


def test_a_symlink_that_stays_inside_is_followed(tmp_path: Path) -> None:
    folder = _robot(tmp_path)
    (folder / "mjcf" / "link.xml").symlink_to(folder / "mjcf" / "rizon4.xml")
    assert resolve_mjcf_uri("file:mjcf/link.xml", folder) == folder / "mjcf" / "rizon4.xml"


def test_the_environment_allows_a_model_outside(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = _robot(tmp_path)
    outside = tmp_path / "x.xml"
    outside.write_text(MODEL, encoding="utf-8")
    monkeypatch.setenv(ALLOW_OUTSIDE_ENV, "1")
    assert resolve_mjcf_uri("file:../../x.xml", folder) == outside
    assert resolve_mjcf_uri(f"file:{outside}", None) == outside


def test_only_the_value_1_allows(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = _robot(tmp_path)
    (tmp_path / "x.xml").write_text(MODEL, encoding="utf-8")
    monkeypatch.setenv(ALLOW_OUTSIDE_ENV, "yes")
    _refusal(folder, "file:../../x.xml")
    assert resolve_mjcf_uri("file:../../x.xml", folder, allow_outside=True).is_file()


# --------------------------------------------------------------------------- inside the MJCF


@pytest.mark.parametrize(
    ("edit", "attribute", "offending"),
    [
        (
            _top('<include file="/etc/hostname"/>'),
            "<include file='/etc/hostname'>",
            "/etc/hostname",
        ),
        (
            _asset('<mesh name="m" file="../../../etc/passwd"/>'),
            "<mesh file='../../../etc/passwd'>",
            "etc/passwd",
        ),
        (
            _asset('<mesh name="m" file="../../../../../../../../../../../../etc/passwd"/>'),
            "<mesh file=",
            "resolves to /etc/passwd,",
        ),
        (
            ('<compiler angle="radian"', '<compiler meshdir="/" angle="radian"'),
            "<compiler meshdir='/'>",
            "resolves to /,",
        ),
        (
            _asset('<texture name="t" type="2d" file="..\\..\\..\\t.png"/>'),
            "<texture file='..\\\\..\\\\..\\\\t.png'>",
            "t.png",
        ),
        (_asset('<mesh name="m" file="c:/etc/passwd"/>'), "<mesh file=", "drive or resource path"),
        (_asset('<skin name="s" file="/etc/passwd"/>'), "<skin file='/etc/passwd'>", "/etc/passwd"),
        (
            _asset('<texture name="c" type="cube" fileright="/etc/passwd"/>'),
            "<texture fileright='/etc/passwd'>",
            "/etc/passwd",
        ),
        (_asset('<model name="sub" file="/etc/passwd"/>'), "<model file='/etc/passwd'>", "/etc/"),
    ],
)
def test_a_reference_leaving_the_folder_is_refused(
    tmp_path: Path, edit: tuple[str, str], attribute: str, offending: str
) -> None:
    folder = _robot(tmp_path, edit)
    message = _refusal(folder)
    assert f"{folder / 'mjcf' / 'rizon4.xml'}:" in message
    assert attribute in message
    assert offending in message
    assert f"outside the robot folder {folder}" in message


def test_a_nested_include_that_escapes_is_refused(tmp_path: Path) -> None:
    folder = _robot(tmp_path, _top('<include file="parts/defaults.xml"/>'))
    (folder / "mjcf" / "parts").mkdir()
    nested = folder / "mjcf" / "parts" / "defaults.xml"
    nested.write_text(
        '<mujoco>\n  <size memory="1M"/>\n  <include file="../../../../secret.xml"/>\n</mujoco>\n',
        encoding="utf-8",
    )
    (tmp_path / "secret.xml").write_text("<mujoco><size/></mujoco>", encoding="utf-8")
    message = _refusal(folder)
    assert f"{nested}:3: <include file='../../../../secret.xml'> resolves to " in message


def test_a_symlinked_mesh_pointing_outside_is_refused(tmp_path: Path) -> None:
    folder = _robot(
        tmp_path,
        ('<compiler angle="radian"', '<compiler meshdir="meshes" angle="radian"'),
        _asset('<mesh name="m" file="part.obj"/>'),
    )
    (tmp_path / "part.obj").write_text(OBJ, encoding="utf-8")
    (folder / "mjcf" / "meshes").mkdir()
    (folder / "mjcf" / "meshes" / "part.obj").symlink_to(tmp_path / "part.obj")
    assert f"resolves to {tmp_path / 'part.obj'}" in _refusal(folder)


def test_references_inside_the_folder_are_accepted_and_compile(tmp_path: Path) -> None:
    folder = _robot(
        tmp_path,
        ('<compiler angle="radian"', '<compiler assetdir="assets" angle="radian"'),
        _asset('<mesh name="m" file="part.obj"/>'),
        _top('<include file="parts/defaults.xml"/>'),
    )
    (folder / "mjcf" / "assets").mkdir()
    (folder / "mjcf" / "assets" / "part.obj").write_text(OBJ, encoding="utf-8")
    (folder / "mjcf" / "parts").mkdir()
    # Nested: resolved next to the including file when not beside the main model.
    (folder / "mjcf" / "parts" / "defaults.xml").write_text(
        '<mujoco><include file="size.xml"/></mujoco>', encoding="utf-8"
    )
    (folder / "mjcf" / "parts" / "size.xml").write_text(
        '<mujoco><size memory="1M"/></mujoco>', encoding="utf-8"
    )
    path = resolve_mjcf_uri(URI, folder)
    assert mujoco.MjModel.from_xml_path(str(path)).nmesh == 1
    assert _check_cli(folder)[0] == 0


# --------------------------------------------------------------------------- unsafe XML


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            '<?xml version="1.0"?>\n<!DOCTYPE m [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>\n'
            '<mujoco model="&b;"/>',
            ":2: a document type declaration (<!DOCTYPE>) is not allowed",
        ),
        (
            '<!DOCTYPE m [<!ENTITY x SYSTEM "file:///etc/passwd">]><mujoco model="&x;"/>',
            ":1: a document type declaration",
        ),
        ('<mujoco model="&x;"/>', ":1:1: not well-formed XML (undefined entity)"),
        ("<mujoco><worldbody></mujoco>", ":1:22: not well-formed XML (mismatched tag)"),
    ],
)
def test_xml_that_cannot_be_read_safely_is_refused(
    tmp_path: Path, text: str, expected: str
) -> None:
    folder = _robot(tmp_path)
    (folder / "mjcf" / "rizon4.xml").write_text(text, encoding="utf-8")
    message = _refusal(folder, outside=False)
    assert f"{folder / 'mjcf' / 'rizon4.xml'}{expected}" in message


def test_a_fifo_is_never_opened(tmp_path: Path) -> None:
    folder = _robot(tmp_path, _top('<include file="pipe.xml"/>'))
    os.mkfifo(folder / "mjcf" / "pipe.xml")
    message = _refusal(folder, outside=False)
    assert "<include file='pipe.xml'> resolves to " in message
    assert "which is not a regular file" in message
    with pytest.raises(MjcfUriError, match="which is not a file"):
        resolve_mjcf_uri("file:mjcf/pipe.xml", folder)


def test_an_include_cycle_ends(tmp_path: Path) -> None:
    folder = _robot(tmp_path, _top('<include file="a.xml"/>'))
    (folder / "mjcf" / "a.xml").write_text('<mujoco><include file="a.xml"/></mujoco>')
    assert resolve_mjcf_uri(URI, folder).name == "rizon4.xml"  # MuJoCo reports the repeat


# --------------------------------------------------------------------------- the CLI


def test_robot_check_refuses_with_one_line(tmp_path: Path) -> None:
    folder = _robot(tmp_path, _top('<include file="/etc/hostname"/>'))
    code, output = _check_cli(folder)
    assert code == 1
    lines = [line for line in output.splitlines() if line.startswith("✗")]
    assert len(lines) == 1
    assert f"{folder / 'mjcf' / 'rizon4.xml'}:9: <include file='/etc/hostname'>" in lines[0]


def test_robot_check_subprocess_refuses_then_allows(tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "part.obj").write_text(OBJ, encoding="utf-8")
    folder = _robot(tmp_path, _asset(f'<mesh name="m" file="{outside / "part.obj"}"/>'))
    command = [sys.executable, "-m", "openral_cli.main", "robot", "check", str(folder)]
    env = {**os.environ, "COLUMNS": "400"}
    env.pop(ALLOW_OUTSIDE_ENV, None)
    refused = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    assert refused.returncode == 1
    assert "Traceback" not in refused.stderr
    assert f"<mesh file='{outside / 'part.obj'}'> resolves to {outside / 'part.obj'}" in (
        refused.stderr
    )
    env[ALLOW_OUTSIDE_ENV] = "1"
    allowed = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    assert allowed.returncode == 0, allowed.stderr


def test_robot_check_allows_a_model_outside_with_the_environment(tmp_path: Path) -> None:
    folder = _robot(tmp_path)
    shutil.copy(folder / "mjcf" / "rizon4.xml", tmp_path / "rizon4.xml")
    _set_uri(folder, "file:../../rizon4.xml")
    code, output = _check_cli(folder)
    assert code == 1 and "resolves to" in output
    assert _check_cli(folder, allowed=True)[0] == 0


# --------------------------------------------------------------------------- packages


def test_package_models_are_confined_to_their_distribution_folder() -> None:
    path, confinement = locate_mjcf_uri(
        "pkg:gym-aloha/gym_aloha/assets/bimanual_viperx_transfer_cube.xml"
    )
    assert confinement is not None
    assert confinement.root.name == "gym_aloha" and confinement.contains(path)
    assert "gym-aloha" in confinement.label
    path, confinement = locate_mjcf_uri("pkg:openarm-mujoco/openarm_mujoco/v2/openarm_bimanual.xml")
    assert confinement is not None and confinement.contains(path)
    assert confinement.root.parts[-3:] == ("share", "openarm_mujoco", "v2")


def test_a_package_model_naming_a_file_outside_its_folder_is_refused(tmp_path: Path) -> None:
    package = tmp_path / "site-packages" / "some_models"
    package.mkdir(parents=True)
    (tmp_path / "site-packages" / "other.obj").write_text(OBJ, encoding="utf-8")
    model = package / "arm.xml"
    model.write_text('<mujoco><asset><mesh file="../other.obj"/></asset></mujoco>')
    with pytest.raises(MjcfConfinementError, match=r"arm.xml:1: <mesh file='../other.obj'>"):
        check_mjcf_files(model, Confinement.of(package, "the files of some-models 1.0"))


def test_scaffold_needs_allow_outside_for_a_model_outside(tmp_path: Path) -> None:
    outside = tmp_path / "rizon4.xml"
    outside.write_text(MODEL, encoding="utf-8")
    folder = tmp_path / "robots" / "my_arm"
    command = [sys.executable, "-m", "openral_cli.main", "robot", "scaffold"]
    command += ["--mjcf", f"file:{outside}", "--name", "my_arm", "--out", str(folder)]
    env = {**os.environ, "COLUMNS": "400"}
    env.pop(ALLOW_OUTSIDE_ENV, None)
    refused = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    assert refused.returncode == 1
    assert "Traceback" not in refused.stderr
    assert len(refused.stderr.strip().splitlines()) == 1
    assert f"resolves to {outside}, outside the robot folder {folder}" in refused.stderr
    assert not (folder / "robot.yaml").exists()
    command.append("--allow-outside")
    allowed = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    assert allowed.returncode == 0, allowed.stderr
    assert f"mjcf_uri: file:{outside}" in (folder / "robot.yaml").read_text(encoding="utf-8")
