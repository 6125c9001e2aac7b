"""``openral sim run``: joint states under the manifest's names, one parse per file, and a
stale table or a scene without a robot as one line."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest
from openral_cli.main import app, run
from openral_core import open_robot_by_id
from typer.testing import CliRunner

from tests.conftest import FRANKA, ROBOTS
from tests.parse_count import count_parses, stale_franka_table

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


def run_cli(monkeypatch: pytest.MonkeyPatch, *args: str | Path) -> int:
    """``openral ARGS`` through the console-script entry point; its exit code."""
    monkeypatch.setattr(sys, "argv", ["openral", *map(str, args)])
    try:
        run()
    except SystemExit as stop:
        return int(stop.code or 0)
    return 0


def test_joint_states_use_the_manifest_joint_names_in_manifest_order(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    names = [joint.name for joint in open_robot_by_id("franka_panda").description.joints]
    parses = count_parses(monkeypatch)
    result = CliRunner().invoke(
        app, ["sim", "run", "--config", str(SCENE), "--steps", "3", "--out", str(tmp_path)]
    )
    assert result.exit_code == 0, result.output
    assert parses == {SCENE.resolve(): 1, FRANKA.resolve(): 1}
    records = [json.loads(line) for line in (tmp_path / "joint_states.jsonl").open()]
    assert [record["step"] for record in records] == [0, 1, 2]
    for record in records:
        assert list(record["positions"]) == names  # panda_joint1 …, not the MJCF's joint1
        assert all(math.isfinite(value) for value in record["positions"].values())
    times = [record["time"] for record in records]
    assert times == sorted(times) and times[0] > 0


def test_a_scene_without_robot_takes_the_robot_option_else_one_located_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "anonymous.yaml"
    text = SCENE.read_text()
    assert text.count("robot_id: franka_panda\n") == 1
    scene.write_text(text.replace("robot_id: franka_panda\n", ""))
    assert run_cli(monkeypatch, "sim", "run", "--config", scene, "--steps", "1") == 1
    assert capsys.readouterr().err == (
        f"error: {scene}:1:1: <document>: the scene names no robot and none was given; "
        "add robot_id\n"
    )
    args = ("sim", "run", "--config", scene, "--steps", "1", "--robot", "franka_panda")
    assert run_cli(monkeypatch, *args) == 0
    assert "franka_panda" in capsys.readouterr().out


def test_stale_tables_end_sim_run_with_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    stale_franka_table(tmp_path, monkeypatch)
    assert run_cli(monkeypatch, "sim", "run", "--config", SCENE, "--steps", "1") == 1
    err = capsys.readouterr().err
    assert err == (
        "error: generated/openral_generated/tables/franka_panda.json: stale: made from an "
        "earlier robots/franka_panda/robot.yaml; run `just schema-export`\n"
    )
