"""Cross-field rules of a manifest's ``real`` section (rules 20 to 26, 28 and 29 of
robot.schema.json).

They keep the wiring a real driver reads sound before anything touches a bus: the feetech
driver has its bus, every joint has exactly one motor, no two motors share an id, a joint a
position servo drives fits in one turn of it, and per-joint settings name joints.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from openral_core.models import FeetechBus, Joint, LimitedJoint, RobotDescription
from openral_core.yaml_source import PathKey

Finding = tuple[PathKey, str]
STS_BAUD_RATES = (1_000_000, 500_000, 250_000, 128_000, 115_200, 57_600, 38_400, 19_200)
"""The bus speeds an STS servo can be set to [bit/s]."""


def real_findings(robot: RobotDescription) -> Iterator[Finding]:
    """Every rule violation of ``robot.real`` (nothing without a real section)."""
    real = robot.real
    if real is None:
        return
    if real.driver.value == "feetech" and real.feetech is None:  # rule 20
        yield (
            ("real", "driver"),
            ("the feetech driver needs its bus: add a `feetech` section (servo_model, motors)"),
        )
    for section in ("feetech", "ros2_control"):  # rule 28
        if getattr(real, section) is not None and real.driver.value != section:
            yield (
                ("real", section),
                f"a `{section}` section belongs to `driver: {section}`; this robot's driver "
                f"is {real.driver.value!r}",
            )
    if real.driver.value == "ros2_control":  # rule 28
        for key in ("estop", "shutdown"):
            if getattr(real, key).value != "hold":
                yield (
                    ("real", key),
                    f"a ros2_control driver's {key} is `hold` (its controllers hold the arm; "
                    "cutting torque is the robot driver's own business)",
                )
    if real.feetech is not None:
        yield from _feetech_findings(robot, real.feetech)
    if real.ros2_control is not None:
        yield from _driver_name_findings(robot, real.ros2_control.joint_names or {})


def _driver_name_findings(robot: RobotDescription, renamed: dict[str, str]) -> Iterator[Finding]:
    """Rule 29: joint_names keys are joints; the driver names they give are distinct."""
    base: PathKey = ("real", "ros2_control", "joint_names")
    taken: dict[str, str] = {}
    for joint in robot.joints:
        driver = renamed.get(joint.name, joint.name)
        if driver in taken and taken[driver] != joint.name:  # a repeated name is rule 2's
            yield (
                (*base, joint.name) if joint.name in renamed else base,
                f"joints {taken[driver]!r} and {joint.name!r} both take the driver name "
                f"{driver!r}; each joint needs its own",
            )
        taken.setdefault(driver, joint.name)
    for name in renamed:
        if name not in {joint.name for joint in robot.joints}:
            yield (*base, name), _not_a_joint(name, robot)


def _feetech_findings(robot: RobotDescription, bus: FeetechBus) -> Iterator[Finding]:
    joints = {joint.name: joint for joint in robot.joints}
    base: PathKey = ("real", "feetech")
    seen_joints: dict[str, int] = {}
    seen_ids: dict[int, int] = {}
    for index, motor in enumerate(bus.motors):
        path: PathKey = (*base, "motors", index)
        if motor.joint not in joints:  # rule 21
            yield (*path, "joint"), _not_a_joint(motor.joint, robot)
        elif motor.joint in seen_joints:  # rule 21
            first = seen_joints[motor.joint]
            yield (
                (*path, "joint"),
                (
                    f"joint {motor.joint!r} already has motor {bus.motors[first].id} "
                    f"(motors[{first}]); each joint is driven by exactly one motor"
                ),
            )
        else:
            seen_joints[motor.joint] = index
            yield from _one_turn(joints[motor.joint], (*path, "joint"))
        if motor.id in seen_ids:  # rule 22
            yield (
                (*path, "id"),
                (
                    f"id {motor.id} is already the id of motors[{seen_ids[motor.id]}] "
                    f"({bus.motors[seen_ids[motor.id]].joint}); every motor needs its own id"
                ),
            )
        else:
            seen_ids[motor.id] = index
    missing = [name for name in joints if name not in seen_joints]
    if missing:  # rule 21
        yield (
            (*base, "motors"),
            (f"no motor for joint(s) {', '.join(missing)}; every joint needs exactly one motor"),
        )
    for name in bus.joint_settings or {}:  # rule 24
        if name not in joints:
            yield (*base, "joint_settings", name), _not_a_joint(name, robot)
    if int(bus.baud_rate) not in STS_BAUD_RATES:  # rule 26
        rates = ", ".join(str(rate) for rate in STS_BAUD_RATES)
        yield (
            (*base, "baud_rate"),
            f"{bus.baud_rate} is no rate of STS servos; expected one of {rates}",
        )
    if int(bus.protocol) != 0:  # rule 25
        yield (
            (*base, "protocol"),
            (
                "protocol 1 (SCS servos) has no Sync Read, which the driver reads every joint "
                "with; STS servos use protocol 0"
            ),
        )


def _one_turn(joint: Joint, path: PathKey) -> Iterator[Finding]:
    """Rule 23: a position servo reads one turn; its joint is revolute and fits in it."""
    if not isinstance(joint, LimitedJoint) or joint.type.value != "revolute":
        kind = joint.type.value if isinstance(joint, LimitedJoint) else "continuous"
        yield (
            path,
            (
                f"a Feetech servo in position mode drives a revolute joint with limits; this joint "
                f"is {kind}"
            ),
        )
        return
    low, high = joint.position_limits
    if high - low > 2 * math.pi:
        yield (
            path,
            (
                f"its position_limits span {high - low:.4f} rad, more than one turn of the servo "
                f"({2 * math.pi:.4f} rad), which a position servo cannot tell apart"
            ),
        )


def _not_a_joint(name: str, robot: RobotDescription) -> str:
    names = ", ".join(joint.name for joint in robot.joints)
    return f"{name!r} is not a joint of this robot; expected one of: {names}"
