"""A reply lost on the wire at connect (noise, a busy host) is asked for again: the ping,
the register reads and the acknowledged writes are each tried three times before a motor
counts as silent. On the emulator, not on hardware."""

from __future__ import annotations

import pytest
from openral_hal.errors import ConfigurationError
from openral_real.errors import BusFault
from openral_real.feetech_bus import FeetechBus

from tests.real.conftest import Rig, open_bus

pytestmark = pytest.mark.exclusive  # a reply later than the 50 ms timeout is a lost one: a
# loaded machine (a fresh clone's parallel phase) once lost the third reply too


def test_two_lost_replies_of_one_motor_at_connect_are_asked_again(rig: Rig) -> None:
    rig.bus.emulator.lost[1] = 2  # the first ping's reply and the second's
    hal = rig.hal()
    hal.connect()
    try:
        assert rig.bus.emulator.lost[1] == 0
        assert len(hal.read_state().positions) == 6
    finally:
        hal.disconnect()


def test_three_lost_replies_make_the_motor_silent(rig: Rig) -> None:
    rig.bus.emulator.lost[4] = 3
    with pytest.raises(ConfigurationError, match=r"motor 4 \(wrist_flex\) does not answer"):
        rig.hal().connect()


def _out_of_turn(bus: FeetechBus, times: int) -> list[int]:
    """The SDK's ping reads a late reply of another request as its own ``times`` times
    (it then indexes past the data: IndexError, as seen under load); counts the calls."""
    ping, calls = bus._packets.ping, []

    def crossed(*args: object) -> object:
        calls.append(1)
        if len(calls) <= times:
            raise IndexError("list index out of range")
        return ping(*args)

    bus._packets.ping = crossed
    return calls


def test_a_late_reply_taken_for_another_is_a_failed_try_not_a_crash(rig: Rig) -> None:
    bus = open_bus(rig.robot, rig.path)
    try:
        calls = _out_of_turn(bus, 2)
        bus.check_motors()
        assert len(calls) == 2 + 6  # two crossed tries of motor 1, then each motor once
        _out_of_turn(bus, 99)
        with pytest.raises(BusFault, match=r"motor 1 \(shoulder_pan\) answered out of turn 3"):
            bus.check_motors()
    finally:
        bus.close()


def _single_reads(rig: Rig) -> list[int]:
    """The motors asked for their present block on their own (the emulator's log)."""
    reads = [line.split() for line in rig.bus.lines if " READ " in f" {line} "]
    return [int(words[-3]) for words in reads if words[-2] == "Present_Position"]


def test_a_garbled_reply_in_a_sync_read_is_asked_again_with_the_motors_after_it(
    rig: Rig,
) -> None:
    """Motor 2's reply to the Sync Read fails its checksum: it is asked alone, and so are
    motors 3 to 6, whose replies were flushed with it (before, the next motor seemed silent:
    its reply had been flushed or waded through by the SDK)."""
    bus = open_bus(rig.robot, rig.path)
    try:
        first = bus.read_present()
        rig.bus.emulator.garbled[2] = 1
        asked_before = len(_single_reads(rig))
        again = bus.read_present()
        assert rig.bus.emulator.garbled[2] == 0
        assert _single_reads(rig)[asked_before:] == [2, 3, 4, 5, 6]
        assert len(again) == 6
        for before, after in zip(first, again, strict=True):
            assert abs(after.position - before.position) <= 2  # the arm holds still [steps]
        assert len(bus.read_present()) == 6 and len(_single_reads(rig)) == asked_before + 5
    finally:
        bus.close()
