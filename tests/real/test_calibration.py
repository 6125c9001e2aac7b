"""Tests for calibration.py: LeRobot's calibration files read, written and refused, and what
their numbers mean in radians."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from openral_core import LoadedRobot
from openral_real.calibration import (
    JointScale,
    MotorCalibration,
    calibration_path,
    read_calibration,
    write_calibration,
)
from openral_real.errors import CalibrationError


def _motor(id_: int, homing: int, low: int, high: int) -> dict[str, int]:
    return {
        "id": id_,
        "drive_mode": 0,
        "homing_offset": homing,
        "range_min": low,
        "range_max": high,
    }


LEROBOT_FILE = {
    "shoulder_pan": _motor(1, -1470, 758, 3292),
    "shoulder_lift": _motor(2, 157, 612, 3401),
    "elbow_flex": _motor(3, -1276, 851, 3100),
    "wrist_flex": _motor(4, -1390, 960, 3260),
    "wrist_roll": _motor(5, 1312, 0, 4095),
    "gripper": _motor(6, -1445, 2023, 3425),
}
"""A file in the shape LeRobot's so101_follower calibration writes (plausible numbers, made
up for the test; wrist_roll over the whole turn, as LeRobot records a full-turn motor)."""


def _file(tmp_path: Path, document: object, text: str | None = None) -> Path:
    file = tmp_path / "arm.json"
    file.write_text(text if text is not None else json.dumps(document, indent=4))
    return file


def test_a_lerobot_file_reads_and_writes_back_the_same(tmp_path: Path, so101: LoadedRobot) -> None:
    bus = so101.tables.real.feetech  # type: ignore[union-attr]
    found = read_calibration(_file(tmp_path, LEROBOT_FILE), so101.description, bus)
    assert found["gripper"] == MotorCalibration(6, 0, -1445, 2023, 3425)
    again = tmp_path / "again.json"
    write_calibration(again, found)
    assert json.loads(again.read_text()) == LEROBOT_FILE


@pytest.mark.parametrize(
    ("edit", "pattern"),
    [
        (lambda d: d.pop("gripper"), r"calibrates motors .* but so101 has .*another robot's"),
        (lambda d: d.update(jaw=d.pop("gripper")), r"another robot's calibration"),
        (lambda d: d["elbow_flex"].update(id=9), r":\d+:\d+: motor elbow_flex has id 9 here but 3"),
        (lambda d: d["wrist_flex"].update(range_min=4000), r":\d+:\d+: motor wrist_flex: range"),
        (lambda d: d["shoulder_pan"].update(drive_mode="0"), r"shoulder_pan.drive_mode must be an"),
        (lambda d: d["shoulder_pan"].pop("homing_offset"), r"motor shoulder_pan needs exactly"),
        (lambda d: d["shoulder_pan"].update(homing_offset=3000), r"homing_offset 3000 is outside"),
    ],
)
def test_a_wrong_file_is_one_line_naming_file_and_place(
    tmp_path: Path, so101: LoadedRobot, edit: object, pattern: str
) -> None:
    document = json.loads(json.dumps(LEROBOT_FILE))
    edit(document)  # type: ignore[operator]
    file = _file(tmp_path, document)
    with pytest.raises(CalibrationError) as raised:
        read_calibration(file, so101.description, so101.tables.real.feetech)  # type: ignore[union-attr]
    message = str(raised.value)
    assert message.startswith(str(file)) and "\n" not in message
    assert re.search(pattern, message), message


def test_broken_json_names_line_and_column(tmp_path: Path, so101: LoadedRobot) -> None:
    file = _file(tmp_path, None, text='{\n  "shoulder_pan": {"id": 1,,}\n}')
    with pytest.raises(CalibrationError, match=rf"^{re.escape(str(file))}:2:\d+: "):
        read_calibration(file, so101.description, so101.tables.real.feetech)  # type: ignore[union-attr]


def test_a_missing_file_says_how_to_make_one(tmp_path: Path, so101: LoadedRobot) -> None:
    with pytest.raises(CalibrationError, match="openral robot calibrate so101"):
        read_calibration(tmp_path / "none.json", so101.description, so101.tables.real.feetech)  # type: ignore[union-attr]


def test_the_file_is_found_where_lerobot_keeps_it(
    tmp_path: Path, so101: LoadedRobot, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("HF_LEROBOT_CALIBRATION", str(tmp_path))
    bus = so101.tables.real.feetech
    assert bus is not None
    path = calibration_path("so101", bus, "my_follower", None)
    assert path == tmp_path / "robots" / "so101_follower" / "my_follower.json"
    assert calibration_path("so101", bus, None, None).name == "so101.json"


@given(
    low=st.integers(0, 2000),
    span=st.integers(100, 2095),
    drive=st.sampled_from([0, 1]),
    centre=st.floats(-1.0, 1.0),
    steps=st.integers(0, 4095),
)
def test_steps_and_radians_round_trip_inside_the_range(
    low: int, span: int, drive: int, centre: float, steps: int
) -> None:
    scale = JointScale(MotorCalibration(1, drive, 0, low, low + span), centre, 4096 / (2 * math.pi))
    inside = min(max(steps, low), low + span)
    assert scale.steps(scale.angle(inside)) == inside
    assert scale.angle(2047) == pytest.approx(centre)  # the homing pose
