"""Tests for bus_console.py: the emulator's console obeys its commands and refuses the rest
in one line, changing nothing."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from openral_core import LoadedRobot
from openral_real.emulator.bus_console import ConsoleError, obey
from openral_real.emulator.bus_emulator import Fault
from openral_real.emulator.emulated_bus import EmulatedBus


@pytest.fixture
def bus(so101: LoadedRobot) -> Iterator[EmulatedBus]:
    with EmulatedBus(so101, seed=2) as emulated:
        yield emulated


def test_faults_go_to_the_motor_named_by_id_or_joint(bus: EmulatedBus) -> None:
    assert obey("silent 3", bus) == "ok: motor 3 is silent"
    assert obey("overload gripper", bus) == "ok: motor 6 is overload"
    assert bus.emulator.faults[3] == {Fault.SILENT} and bus.emulator.faults[6] == {Fault.OVERLOAD}
    assert "checksum" in obey("checksum 0.5", bus) and bus.emulator.corrupt_share == 0.5
    assert obey("clear", bus) == "ok: no faults"
    assert all(not faults for faults in bus.emulator.faults.values())
    assert bus.emulator.corrupt_share == 0.0


def test_a_hand_moves_a_joint_and_status_shows_it(bus: EmulatedBus) -> None:
    assert obey("move shoulder_pan 0.5", bus) == "ok: shoulder_pan at 0.5 rad"
    raw = bus.arm.shafts()[0].raw
    assert bus.arm.angle_of(0, raw) == pytest.approx(0.5, abs=1e-3)
    assert obey("status", bus).startswith(f"{bus.path}; 1: pos ")


def test_unplug_and_replug_make_a_new_port(bus: EmulatedBus) -> None:
    old = bus.path
    assert obey("unplug", bus) == "ok: unplugged" and bus.path == ""
    reply = obey("replug", bus)
    assert reply.startswith("ok: plugged in at /dev/pts/") and bus.path != ""
    assert old  # the first port existed


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("explode", "unknown command 'explode'"),
        ("silent elbow", "no motor 'elbow'; motors: 1=shoulder_pan"),
        ("silent", "silent takes one argument"),
        ("checksum 1.5", "checksum SHARE must be within 0..1"),
        ("checksum nan", "SHARE must be finite"),
        ("move shoulder_pan fast", "RADIANS must be a number"),
        ("move nose 0.1", "move JOINT RADIANS, or move middle"),
        ("clear now", "clear takes no arguments"),
    ],
)
def test_a_bad_command_is_one_line_and_changes_nothing(
    bus: EmulatedBus, line: str, message: str
) -> None:
    before = [s.get("Present_Position") for s in bus.emulator.servos.values()]
    with pytest.raises(ConsoleError, match=message) as raised:
        obey(line, bus)
    assert "\n" not in str(raised.value)
    assert all(not faults for faults in bus.emulator.faults.values())
    assert [s.get("Present_Position") for s in bus.emulator.servos.values()] == before


def test_a_scene_can_move_the_emulated_shafts(so101: LoadedRobot) -> None:
    """`openral sim bus so101 --scene ...`: the servos answer from the scene's arm."""
    from openral_core.loader import load_scene
    from openral_core.paths import repo_root

    from tests.real.conftest import open_bus

    scene = load_scene(repo_root() / "robots" / "so101" / "scenes" / "tabletop.yaml")
    with EmulatedBus(so101, scene=scene, seed=1) as emulated:
        bus = open_bus(so101, emulated.path)
        try:
            bus.check_motors()
            readings = bus.read_present()
        finally:
            bus.close()
        with pytest.raises(ConsoleError, match="not a scene's arm"):
            obey("move shoulder_pan 0.3", emulated)
    assert len(readings) == 6 and all(0 <= r.position < 4096 for r in readings)
