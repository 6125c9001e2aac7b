"""Tests for `openral robot`: list, show, validate and their exit codes."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from openral_cli.main import app
from openral_core import robot_ids
from typer.testing import CliRunner

from tests.conftest import FRANKA, ROBOTS, ManifestWriter

runner = CliRunner()


def test_list_shows_every_robot_with_its_counts() -> None:
    result = runner.invoke(app, ["robot", "list"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    for robot_id in robot_ids(ROBOTS):
        assert robot_id in result.output
    franka_row = next(line for line in result.output.splitlines() if "franka_panda" in line)
    cells = [cell.strip() for cell in franka_row.split("│")]
    assert cells[2:5] == ["8", "1", "agentview, wrist"]


def test_show_prints_wiring_and_slot_tables() -> None:
    result = runner.invoke(app, ["robot", "show", "franka_panda"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    assert "panda_joint4" in result.output and "joint4" in result.output
    assert "camera1" in result.output and "sum_over_scale" in result.output


def test_validate_all_passes_on_the_repository() -> None:
    result = runner.invoke(app, ["robot", "validate", "--all"])
    assert result.exit_code == 0, result.output
    assert result.output.count(": OK") == len(robot_ids(ROBOTS))


def test_validate_bad_file_exits_1_with_located_message(write_manifest: ManifestWriter) -> None:
    path = write_manifest(("base: fixed", "base: fixed\nbase: mobile"))
    result = runner.invoke(app, ["robot", "validate", str(path)])
    assert result.exit_code == 1
    assert f"{path}:7:1: base: duplicate key 'base': also defined on line 6" in result.output


def test_validate_accepts_ids_folders_and_files() -> None:
    result = runner.invoke(
        app, ["robot", "validate", "franka_panda", str(FRANKA.parent), str(FRANKA)]
    )
    assert result.exit_code == 0, result.output
    assert result.output.count(": OK") == 3


def test_validate_without_targets_is_a_usage_error() -> None:
    assert runner.invoke(app, ["robot", "validate"]).exit_code == 2


@pytest.mark.parametrize(
    "command", [["robot", "show", "no_such_robot"], ["robot", "validate", "no_such_robot"]]
)
def test_unknown_robot_is_one_clear_error_without_traceback(command: list[str]) -> None:
    cli = Path(sys.executable).with_name("openral")
    result = subprocess.run([str(cli), *command], capture_output=True, text=True, check=False)
    assert result.returncode == 1
    assert "unknown robot 'no_such_robot'; known robots:" in result.stderr
    assert "Traceback" not in result.stderr + result.stdout


def test_an_error_with_brackets_is_printed_verbatim(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from openral_cli import main
    from openral_core.errors import OpenralError

    def fail(**kwargs: object) -> None:
        raise OpenralError("expected slots [camera1, camera2], saw [camera1]")

    monkeypatch.setattr(main, "app", fail)
    with pytest.raises(SystemExit) as exit_:
        main.run()
    assert exit_.value.code == 1
    assert "expected slots [camera1, camera2], saw [camera1]" in capsys.readouterr().err


def test_check_names_the_manifest_once_when_it_cannot_load(write_manifest: ManifestWriter) -> None:
    invalid = write_manifest(("base: fixed", "base: fixed\nbase: mobile"), folder="invalid")
    broken = write_manifest(folder="mock_arm")
    model = '<mujoco><worldbody><body><geom type="nosuch"/></body></worldbody></mujoco>'
    (broken.parent / "mock_arm.xml").write_text(model)  # well-formed XML MuJoCo refuses
    result = runner.invoke(app, ["robot", "check", str(invalid), str(broken)])
    assert result.exit_code == 1
    assert f"✗ {invalid}:7:1: base: duplicate key 'base'" in result.output  # one located line
    assert f"{invalid}: {invalid}" not in result.output
    unloadable = (
        rf"✗ {re.escape(str(broken))}:\d+:\d+: sim\.mjcf_uri: .*mock_arm\.xml does not load"
    )
    assert re.search(
        unloadable + r" in MuJoCo: XML Error: invalid keyword: 'nosuch'", result.output
    )
