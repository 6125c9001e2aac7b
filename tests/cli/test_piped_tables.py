"""Tables printed into a pipe keep their natural width; a terminal width is still honoured."""

from __future__ import annotations

import os
import subprocess
import sys

OPENRAL = [sys.executable, "-m", "openral_cli.main"]


def _show_franka(columns: str | None) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
    if columns is not None:
        env["COLUMNS"] = columns
    result = subprocess.run(
        [*OPENRAL, "robot", "show", "franka_panda"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    return result.stdout.splitlines()


def _rows(lines: list[str]) -> list[str]:
    return [line for line in lines if line.startswith("│")]


def test_a_piped_table_is_printed_unwrapped_at_its_natural_width() -> None:
    lines = _show_franka(None)
    rows = _rows(lines)
    joint_rows = [row for row in rows if "revolute" in row or "prismatic" in row]
    assert len(joint_rows) == 8, "one line per joint: no cell wrapped onto a second line"
    assert any("│ panda_finger_joint1 │" in row for row in rows), "no cell cut with …"
    assert max(len(line) for line in lines) > 80


def test_an_explicit_columns_still_bounds_the_width() -> None:
    lines = _show_franka("60")
    assert max(len(line) for line in _rows(lines)) <= 60
