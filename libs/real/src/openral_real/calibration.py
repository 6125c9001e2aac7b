"""An arm's calibration in LeRobot's format, and what it means in the manifest's units.

The file (``<arm id>.json``) holds, per motor by joint name: its bus ``id``, ``drive_mode``
(1: the servo counts the other way than the joint turns), ``homing_offset`` (what the
servo's Homing_Offset register holds: its present position is the encoder's reading less
this) and ``range_min``/``range_max`` (the present positions at the ends of the joint's
travel, recorded while the arm was moved by hand). So an arm calibrated with LeRobot works
here as it is, and a file written here works in LeRobot.

How present positions become radians (:class:`JointScale`): the homing pose, where the
present position reads 2047 (half a turn) after calibration, is the middle of the joint's
``position_limits`` (where the user held it: "the middle of its range"); 4096 steps (the
servo's resolution) are one turn; ``drive_mode`` 1 turns the sign. The recorded range
bounds the goals. Anchoring the angle at the homing pose, not at the middle of the
recorded range (LeRobot's degrees), keeps the reading true where a joint cannot be swept
evenly: an SO-101's elbow folds onto its upper arm before its upper limit, so its recorded
range is lopsided. Two calibrations homed in the same pose, LeRobot's or this driver's,
read the same radians whatever ranges they recorded.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict, dataclass
from pathlib import Path

from openral_core.models import LimitedJoint, RobotDescription
from openral_core.real_wiring import FeetechWiring

from openral_real.errors import CalibrationError

FIELDS = ("id", "drive_mode", "homing_offset", "range_min", "range_max")
HOMING_LIMIT = 2047
"""Largest homing offset the 11-bit sign-magnitude register holds [steps]."""
HALF_TURN = 2047
"""What a homed servo reads in the homing pose [steps] (LeRobot's ``int(4095 / 2)``)."""


@dataclass(frozen=True)
class MotorCalibration:
    """One motor's calibration (LeRobot's fields)."""

    id: int
    drive_mode: int
    homing_offset: int
    range_min: int
    range_max: int


@dataclass(frozen=True)
class JointScale:
    """Present position [steps] ↔ joint angle [rad] for one motor (see the module doc)."""

    calibration: MotorCalibration
    centre_rad: float
    """The middle of the joint's position limits [rad]: its angle in the homing pose."""
    steps_per_rad: float

    @property
    def sign(self) -> float:
        """-1 when the servo counts against the joint."""
        return -1.0 if self.calibration.drive_mode else 1.0

    def angle(self, steps: float) -> float:
        """The joint angle [rad] at present position ``steps``."""
        return self.centre_rad + self.sign * (steps - HALF_TURN) / self.steps_per_rad

    def steps(self, angle_rad: float) -> int:
        """The present position [steps] of ``angle_rad``, inside the calibrated range."""
        raw = round(HALF_TURN + self.sign * (angle_rad - self.centre_rad) * self.steps_per_rad)
        return min(max(raw, self.calibration.range_min), self.calibration.range_max)

    def rate(self, steps_per_s: float) -> float:
        """Joint speed [rad/s] of a servo speed [steps/s]."""
        return self.sign * steps_per_s / self.steps_per_rad


def joint_scales(
    robot: RobotDescription, bus: FeetechWiring, calibration: dict[str, MotorCalibration]
) -> tuple[JointScale, ...]:
    """One scale per motor, in manifest joint order."""
    joints = {joint.name: joint for joint in robot.joints}
    per_rad = bus.resolution / (2.0 * math.pi)
    scales = []
    for motor in bus.motors:
        joint = joints[motor.joint]
        low, high = joint.position_limits if isinstance(joint, LimitedJoint) else (0.0, 0.0)
        scales.append(JointScale(calibration[motor.joint], (low + high) / 2.0, per_rad))
    return tuple(scales)


def calibration_dir(bus: FeetechWiring) -> Path | None:
    """LeRobot's calibration folder of this robot type (None: the manifest names none):
    ``$HF_LEROBOT_CALIBRATION/robots/<type>``, by default under
    ``$HF_LEROBOT_HOME`` (``~/.cache/huggingface/lerobot``)."""
    if bus.lerobot_robot_type is None:
        return None
    home = Path(os.environ.get("HF_LEROBOT_HOME", "~/.cache/huggingface/lerobot")).expanduser()
    root = Path(os.environ.get("HF_LEROBOT_CALIBRATION", home / "calibration")).expanduser()
    return root / "robots" / bus.lerobot_robot_type


def calibration_path(
    robot_name: str, bus: FeetechWiring, arm_id: str | None, explicit: Path | None
) -> Path:
    """Where an arm's calibration file is: ``explicit`` when given, else ``<arm id>.json``
    (the arm id defaults to the robot's name) in :func:`calibration_dir`.

    Raises:
        CalibrationError: Neither a file nor a calibration folder in the manifest.
    """
    if explicit is not None:
        return explicit
    folder = calibration_dir(bus)
    if folder is None:
        raise CalibrationError(
            f"{robot_name}'s manifest names no calibration folder (real.feetech.calibration); "
            "pass the file: --calibration FILE"
        )
    return folder / f"{arm_id or robot_name}.json"


def read_calibration(
    file: Path, robot: RobotDescription, bus: FeetechWiring
) -> dict[str, MotorCalibration]:
    """The calibration in ``file``, checked against the robot's motors.

    Raises:
        CalibrationError: The file is missing, is not JSON, or calibrates another arm
            (other joints or ids), or a value is out of range; one line naming the file
            (and line:col where JSON says where).
    """
    if not file.is_file():
        raise CalibrationError(
            f"{file}: no calibration file; calibrate the arm first: openral robot calibrate "
            f"{robot.name} --transport PORT (or with LeRobot)"
        )
    text = file.read_text("utf-8", errors="replace")
    try:
        document = json.loads(text)
    except json.JSONDecodeError as error:
        raise CalibrationError(f"{file}:{error.lineno}:{error.colno}: {error.msg}") from None
    if not isinstance(document, dict):
        raise CalibrationError(f"{file}:1:1: expected an object of motors by joint name")
    expected = [motor.joint for motor in bus.motors]
    if set(document) != set(expected):
        raise CalibrationError(
            f"{file}: calibrates motors {', '.join(sorted(document)) or '(none)'}, but "
            f"{robot.name} has {', '.join(expected)}: this is another robot's calibration"
        )
    found = {name: _motor(file, text, name, document[name]) for name in expected}
    for motor in bus.motors:
        if found[motor.joint].id != motor.id:
            raise CalibrationError(
                f"{_where(file, text, motor.joint)}: motor {motor.joint} has id "
                f"{found[motor.joint].id} here but {motor.id} on {robot.name}'s bus: this file "
                "calibrates another arm"
            )
    return found


def write_calibration(file: Path, calibration: dict[str, MotorCalibration]) -> None:
    """Write ``calibration`` as LeRobot does (an indented object in joint order)."""
    file.parent.mkdir(parents=True, exist_ok=True)
    document = {name: asdict(motor) for name, motor in calibration.items()}
    file.write_text(json.dumps(document, indent=4) + "\n", "utf-8")


def _motor(file: Path, text: str, name: str, entry: object) -> MotorCalibration:
    if not isinstance(entry, dict) or set(entry) != set(FIELDS):
        raise CalibrationError(
            f"{_where(file, text, name)}: motor {name} needs exactly {', '.join(FIELDS)}"
        )
    values = {}
    for field in FIELDS:
        value = entry[field]
        if not isinstance(value, int) or isinstance(value, bool):
            raise CalibrationError(
                f"{_where(file, text, name, field)}: {name}.{field} must be an integer, "
                f"got {value!r}"
            )
        values[field] = value
    motor = MotorCalibration(**values)
    problem = _range_problem(motor)
    if problem:
        raise CalibrationError(f"{_where(file, text, name)}: motor {name}: {problem}")
    return motor


def _range_problem(motor: MotorCalibration) -> str:
    if motor.drive_mode not in (0, 1):
        return f"drive_mode is {motor.drive_mode}; expected 0 or 1"
    if abs(motor.homing_offset) > HOMING_LIMIT:
        return f"homing_offset {motor.homing_offset} is outside ±{HOMING_LIMIT}"
    if not 0 <= motor.range_min < motor.range_max <= 4095:
        return f"range {motor.range_min}..{motor.range_max} is not inside 0..4095 in order"
    return ""


def _where(file: Path, text: str, motor: str, field: str | None = None) -> str:
    """``file:line:col`` of a motor's key (or of a field's key after it) in ``text``."""
    at = text.find(f'"{motor}"')
    if at >= 0 and field is not None:
        after = text.find(f'"{field}"', at)
        at = after if after >= 0 else at
    if at < 0:
        return str(file)
    line = text.count("\n", 0, at) + 1
    column = at - (text.rfind("\n", 0, at) + 1) + 1
    return f"{file}:{line}:{column}"
