"""``openral sim sweep`` refuses arguments it could not honour before any episode runs, in
one line and leaving nothing behind: an ``--out`` that is a file or under one, a seed or
a scene given twice, an empty seed range."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer
from openral_cli.commands.sweep import check_distinct_scenes, check_out_dir, parse_seeds

from tests.conftest import ROBOTS

OPENRAL = Path(sys.executable).parent / "openral"
TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("1,1,1", "'1,1,1' gives seed 1 more than once; each seed runs once"),
        ("4,2,4,2", "gives seed 2 more than once"),
        ("5:2", "'5:2' is an empty range: STOP must be greater than START"),
        ("3:3", "is an empty range"),
        ("-1", "gives a negative seed"),
        ("-2:1", "gives a negative seed"),
    ],
)
def test_seeds_that_would_run_an_episode_twice_or_none_are_refused(text: str, words: str) -> None:
    with pytest.raises(typer.BadParameter, match=words):
        parse_seeds(text)


def test_distinct_seeds_keep_their_order() -> None:
    assert parse_seeds("9,2,5") == [9, 2, 5]
    assert parse_seeds("3:6") == [3, 4, 5]


def test_a_scene_given_twice_is_refused_also_by_another_spelling(tmp_path: Path) -> None:
    scene = tmp_path / "s.yaml"
    again = tmp_path / "sub" / ".." / "s.yaml"
    (tmp_path / "sub").mkdir()
    with pytest.raises(typer.BadParameter, match="is given more than once; each scene runs once"):
        check_distinct_scenes([scene, tmp_path / "t.yaml", again])
    check_distinct_scenes([scene, tmp_path / "t.yaml"])


def test_an_out_that_is_a_file_or_under_one_is_refused_and_nothing_is_made(
    tmp_path: Path,
) -> None:
    afile = tmp_path / "afile"
    afile.write_text("x")
    with pytest.raises(typer.BadParameter, match=r"afile is a file; expected a folder"):
        check_out_dir(afile)
    with pytest.raises(typer.BadParameter, match=r"deeper is under .*afile, which is a file"):
        check_out_dir(afile / "sub" / "deeper")
    check_out_dir(tmp_path / "new" / "folder")  # may be made: accepted ...
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]  # ... but not made yet


def test_the_command_line_prints_a_bad_out_in_one_box_before_any_episode(tmp_path: Path) -> None:
    afile = tmp_path / "afile"
    afile.write_text("x")
    command = [str(OPENRAL), "sim", "sweep", "--config", str(TABLETOP), "--seeds", "0:2"]
    command += ["--policy", "wave", "--out", str(afile / "results")]
    env = {**os.environ, "COLUMNS": "400"}  # the error box on one line
    result = subprocess.run(command, capture_output=True, text=True, timeout=120, env=env)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert "Invalid value for --out" in result.stderr and "which is a file" in result.stderr
    assert afile.read_text() == "x"
