"""A reply lost on the wire at connect (noise, a busy host) is asked for again: the ping,
the register reads and the acknowledged writes are each tried three times before a motor
counts as silent. On the emulator, not on hardware."""

from __future__ import annotations

import pytest
from openral_hal.errors import ConfigurationError

from tests.real.conftest import Rig


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
