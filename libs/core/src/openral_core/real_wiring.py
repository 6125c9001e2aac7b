"""The real-robot table of a manifest: its ``real`` section with every default filled in.

What a real driver consumes (``generated/openral_generated/tables/<id>.json``, key
``real``): the driver kind, its control rate, the E-stop and shutdown behaviour, and for a
Feetech bus one row per motor in manifest joint order (joint, bus id, the registers written
at connect) plus the servo model's identity and control table, so the driver needs nothing
but this table and its calibration file; for a ros2_control driver, its topic, controller
and action names and the driver's name of every manifest joint.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from openral_core.models import (
    FeetechBus,
    FeetechSettings,
    RealDescription,
    RobotDescription,
    Ros2ControlDriver,
)
from openral_core.servo_models import SERVO_MODELS


@dataclass(frozen=True)
class MotorWiring:
    """One servo on the bus."""

    joint: str
    """The manifest joint it drives."""
    id: int
    """Its bus id."""
    settings: dict[str, int]
    """Registers written at connect (``settings`` overlaid by ``joint_settings``)."""


@dataclass(frozen=True)
class FeetechWiring:
    """A Feetech bus with every default filled in."""

    baud_rate: int
    protocol: int
    servo_model: str
    model_number: int
    """What every servo must answer at Model_Number."""
    resolution: int
    """Position steps per turn."""
    motors: tuple[MotorWiring, ...]
    """One per manifest joint, in manifest order."""
    reply_timeout_s: float
    """How long a servo may take to answer before it counts as silent [s]."""
    lerobot_robot_type: str | None
    """LeRobot's calibration folder name (None: only an explicit calibration file)."""
    registers: dict[str, tuple[int, int]]
    """The servo model's control table: name → (address, size in bytes)."""
    sign_bits: dict[str, int]
    """Sign-magnitude registers → their sign bit."""

    @property
    def ids(self) -> tuple[int, ...]:
        """Bus ids in manifest joint order."""
        return tuple(motor.id for motor in self.motors)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> FeetechWiring:
        """Inverse of ``dataclasses.asdict``."""
        return cls(
            **{
                **data,
                "motors": tuple(MotorWiring(**motor) for motor in data["motors"]),
                "registers": {k: (v[0], v[1]) for k, v in data["registers"].items()},
            }
        )


@dataclass(frozen=True)
class Ros2ControlWiring:
    """A ros2_control robot driver with every default filled in (names relative to its
    namespace)."""

    joint_state_topic: str
    controller: str
    command_interface: str
    """``topic`` or ``action``."""
    gripper_action: str | None
    """The GripperCommand action (None: grippers go with the arm's trajectory)."""
    driver_joints: tuple[str, ...]
    """The driver's name of each manifest joint, in manifest order."""

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Ros2ControlWiring:
        """Inverse of ``dataclasses.asdict``."""
        return cls(**{**data, "driver_joints": tuple(data["driver_joints"])})


@dataclass(frozen=True)
class RealWiring:
    """A robot's real driver with every default filled in (see RealDescription)."""

    driver: str
    control_rate_hz: float
    estop: str
    """``hold`` or ``torque_off``."""
    shutdown: str
    """``hold`` or ``torque_off``."""
    first_motion_speed_scale: float
    refuse_zero_action: bool
    feetech: FeetechWiring | None
    ros2_control: Ros2ControlWiring | None

    @property
    def control_period_s(self) -> float:
        """One read-and-write cycle [s]."""
        return 1.0 / self.control_rate_hz

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RealWiring:
        """Inverse of ``dataclasses.asdict`` (the ``real`` of a tables JSON file)."""
        bus, ros = data.get("feetech"), data.get("ros2_control")
        return cls(
            **{
                **data,
                "feetech": None if bus is None else FeetechWiring.from_dict(bus),
                "ros2_control": None if ros is None else Ros2ControlWiring.from_dict(ros),
            }
        )


def real_wiring(robot: RobotDescription) -> RealWiring | None:
    """The robot's real section resolved, or None without one (the rules hold: a
    ``feetech`` driver has its section and every joint its motor)."""
    real: RealDescription | None = robot.real
    if real is None:
        return None
    return RealWiring(
        driver=real.driver.value,
        control_rate_hz=float(real.control_rate_hz),
        estop=real.estop.value,
        shutdown=real.shutdown.value,
        first_motion_speed_scale=float(real.first_motion_speed_scale),
        refuse_zero_action=real.refuse_zero_action,
        feetech=_feetech(robot, real.feetech) if real.feetech is not None else None,
        ros2_control=(
            _ros2_control(robot, real.ros2_control or Ros2ControlDriver())
            if real.driver.value == "ros2_control"
            else None
        ),
    )


def _ros2_control(robot: RobotDescription, driver: Ros2ControlDriver) -> Ros2ControlWiring:
    renamed = driver.joint_names or {}
    return Ros2ControlWiring(
        joint_state_topic=str(driver.joint_state_topic),
        controller=str(driver.controller),
        command_interface=driver.command_interface.value,
        gripper_action=None if driver.gripper_action is None else str(driver.gripper_action),
        driver_joints=tuple(renamed.get(joint.name, joint.name) for joint in robot.joints),
    )


def _feetech(robot: RobotDescription, bus: FeetechBus) -> FeetechWiring:
    model = SERVO_MODELS[bus.servo_model.value]
    common = _settings(bus.settings)
    ids = {motor.joint: motor.id for motor in bus.motors}
    per_joint = bus.joint_settings or {}
    motors = tuple(
        MotorWiring(
            joint=joint.name,
            id=ids[joint.name],
            settings={**common, **_settings(per_joint.get(joint.name))},
        )
        for joint in robot.joints
        if joint.name in ids
    )
    return FeetechWiring(
        baud_rate=int(bus.baud_rate),
        protocol=int(bus.protocol),
        servo_model=model.name,
        model_number=model.model_number,
        resolution=model.resolution,
        motors=motors,
        reply_timeout_s=float(bus.reply_timeout_ms) / 1000.0,
        lerobot_robot_type=bus.calibration.lerobot_robot_type if bus.calibration else None,
        registers=dict(model.registers),
        sign_bits=dict(model.sign_bits),
    )


def _settings(settings: FeetechSettings | None) -> dict[str, int]:
    """The registers a FeetechSettings sets (those left out are not written)."""
    if settings is None:
        return {}
    values: dict[str, int] = settings.model_dump(exclude_none=True)
    return values
