"""The emulator's console: one command a line in, one line out (``openral sim bus``'s stdin).

Commands (a motor by bus id or joint name):

- ``silent M``, ``overload M``, ``overheat M``, ``voltage M``: give motor M that fault;
- ``checksum SHARE``: that share of replies (0 to 1) goes out with a wrong checksum;
- ``unplug`` / ``replug``: pull the adapter out / plug it in again (a new port);
- ``clear``: every fault ends;
- ``move JOINT RADIANS`` / ``move middle``: a hand puts a joint (or every joint, in the
  middle of its range) where it says, as a user moves an arm whose torque is off;
- ``status``: every motor's present position, goal, torque and faults;
- ``help``.
"""

from __future__ import annotations

from openral_core.models import LimitedJoint

from openral_real.emulator.bus_emulator import Fault
from openral_real.emulator.emulated_bus import EmulatedBus

HELP = (
    "commands: silent|overload|overheat|voltage MOTOR, checksum SHARE, unplug, replug, "
    "clear, move JOINT RADIANS, move middle, status, help (MOTOR: bus id or joint name)"
)


class ConsoleError(ValueError):
    """A command the console does not understand (said back in one line)."""


def obey(line: str, bus: EmulatedBus) -> str:
    """Carry out one console line; what happened, in one line.

    Raises:
        ConsoleError: An unknown command or a bad argument (nothing was changed).
    """
    words = line.split()
    if not words:
        return ""
    verb, args = words[0].lower(), words[1:]
    if verb in {fault.value for fault in Fault}:
        servo_id = _motor(bus, _one(args, verb))
        bus.emulator.inject(servo_id, Fault(verb))
        return f"ok: motor {servo_id} is {verb}"
    if verb == "checksum":
        share = _number(_one(args, verb), "SHARE")
        if not 0.0 <= share <= 1.0:
            raise ConsoleError(f"checksum SHARE must be within 0..1, got {share:g}")
        bus.emulator.corrupt_share = share
        return f"ok: {share:.0%} of replies go out with a wrong checksum"
    if verb in ("unplug", "replug", "clear", "status", "help"):
        if args:
            raise ConsoleError(f"{verb} takes no arguments")
        return _plain(verb, bus)
    if verb == "move":
        return _move(args, bus)
    raise ConsoleError(f"unknown command {verb!r}; {HELP}")


def _plain(verb: str, bus: EmulatedBus) -> str:
    if verb == "unplug":
        bus.pty.unplug()
        return "ok: unplugged"
    if verb == "replug":
        return f"ok: plugged in at {bus.pty.replug()}"
    if verb == "clear":
        bus.emulator.clear()
        return "ok: no faults"
    if verb == "status":
        return _status(bus)
    return HELP


def _move(args: list[str], bus: EmulatedBus) -> str:
    joints = {joint.name: joint for joint in bus.robot.description.joints}
    if args == ["middle"]:
        for joint in joints.values():
            if isinstance(joint, LimitedJoint):
                bus.arm.place(joint.name, sum(joint.position_limits) / 2.0)
        return "ok: every joint in the middle of its range"
    if len(args) != 2 or args[0] not in joints:
        raise ConsoleError(f"move JOINT RADIANS, or move middle; joints: {', '.join(joints)}")
    angle = _number(args[1], "RADIANS")
    try:
        bus.arm.place(args[0], angle)
    except ValueError as error:
        raise ConsoleError(str(error)) from None
    return f"ok: {args[0]} at {angle:g} rad"


def _status(bus: EmulatedBus) -> str:
    bus.emulator.refresh()
    parts = []
    for servo_id, servo in bus.emulator.servos.items():
        faults = ",".join(sorted(f.value for f in bus.emulator.faults[servo_id])) or "-"
        parts.append(
            f"{servo_id}: pos {servo.get('Present_Position')} goal {servo.get('Goal_Position')} "
            f"torque {servo.get('Torque_Enable')} faults {faults}"
        )
    plugged = bus.path or "unplugged"
    return f"{plugged}; " + "; ".join(parts)


def _motor(bus: EmulatedBus, word: str) -> int:
    by_joint = {motor.joint: motor.id for motor in bus.wiring.motors}
    if word in by_joint:
        return by_joint[word]
    if word.isdigit() and int(word) in bus.emulator.servos:
        return int(word)
    known = ", ".join(f"{motor.id}={motor.joint}" for motor in bus.wiring.motors)
    raise ConsoleError(f"no motor {word!r}; motors: {known}")


def _one(args: list[str], verb: str) -> str:
    if len(args) != 1:
        raise ConsoleError(f"{verb} takes one argument; {HELP}")
    return args[0]


def _number(word: str, what: str) -> float:
    try:
        value = float(word)
    except ValueError:
        raise ConsoleError(f"{what} must be a number, got {word!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise ConsoleError(f"{what} must be finite, got {word!r}")
    return value
