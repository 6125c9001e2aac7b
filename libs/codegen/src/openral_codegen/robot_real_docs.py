"""The "Real robot" section of a robot's page, from its real table (``real`` in the
manifest, defaults filled in by ``openral_core.real_wiring``)."""

from __future__ import annotations

from openral_core.real_wiring import FeetechWiring, RealWiring


def real_section(name: str, real: RealWiring | None) -> str:
    """The section: how ``deploy real`` reaches the robot, or that it cannot."""
    if real is None:
        return (
            "## Real robot\n\nNo `real` section: this robot has no real driver here "
            '(`deploy real` and `build_hal(mode="real")` refuse it).\n'
        )
    lines = [
        "## Real robot\n",
        f"`openral deploy real --robot {name} --transport PORT` drives it through the "
        f"`{real.driver}` driver ([Run it on a real SO-101](../tutorials/real-so101.md) walks "
        "through one).\n",
        "| Setting | Value |",
        "|---|---|",
        f"| Control rate | {real.control_rate_hz:g} Hz (one bus reading and one write per "
        f"{real.control_period_s * 1000:g} ms) |",
        f"| E-stop | `{real.estop}` |",
        f"| When the driver stops | hold, then `{real.shutdown}` |",
        f"| First motion | at {real.first_motion_speed_scale:g} of the velocity limits |",
        f"| All-zero actions | {'refused' if real.refuse_zero_action else 'accepted'} |",
    ]
    if real.feetech is not None:
        lines += _bus_rows(real.feetech)
        lines += ["", *_motor_table(real.feetech)]
    return "\n".join(lines) + "\n"


def _bus_rows(bus: FeetechWiring) -> list[str]:
    folder = (
        f"LeRobot's `robots/{bus.lerobot_robot_type}/<arm id>.json`"
        if bus.lerobot_robot_type
        else "given with `--calibration`"
    )
    return [
        f"| Servos | Feetech `{bus.servo_model}` (model number {bus.model_number}, "
        f"{bus.resolution} steps a turn), protocol {bus.protocol} |",
        f"| Bus | {bus.baud_rate} baud; a servo silent for {bus.reply_timeout_s * 1000:g} ms "
        "latches the E-stop |",
        f"| Calibration | {folder} |",
    ]


def _motor_table(bus: FeetechWiring) -> list[str]:
    rows = ["| Joint | Bus id | Written at connect |", "|---|---|---|"]
    for motor in bus.motors:
        settings = ", ".join(f"{k} {v}" for k, v in motor.settings.items()) or "-"
        rows.append(f"| `{motor.joint}` | {motor.id} | {settings} |")
    return rows
