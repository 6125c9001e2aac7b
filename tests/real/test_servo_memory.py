"""Tests for servo_memory.py and servo_motion.py: the emulated servo keeps what a servo keeps
and moves as a servo moves."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from openral_core.servo_models import SERVO_MODELS, fault_text
from openral_real.emulator.servo_memory import (
    ServoMemory,
    from_sign_magnitude,
    to_sign_magnitude,
)
from openral_real.emulator.servo_motion import ServoProfile

STS = SERVO_MODELS["sts3215"]


def _write(servo: ServoMemory, name: str, value: int) -> list[str]:
    address, size = STS.registers[name]
    return servo.write(address, value.to_bytes(size, "little"), raw_position=2000)


def test_a_fresh_servo_answers_its_model_and_id() -> None:
    servo = ServoMemory(STS, 5)
    assert servo.get("Model_Number") == 777 and servo.get("ID") == 5
    assert servo.read(3, 2) == (777).to_bytes(2, "little")


def test_eeprom_keeps_a_write_only_while_unlocked() -> None:
    servo = ServoMemory(STS, 1)
    assert _write(servo, "P_Coefficient", 16) == []  # locked from the factory
    assert servo.get("P_Coefficient") == 32
    _write(servo, "Lock", 0)
    assert _write(servo, "P_Coefficient", 16) == ["P_Coefficient"]
    assert servo.get("P_Coefficient") == 16


def test_read_only_registers_ignore_writes() -> None:
    servo = ServoMemory(STS, 1)
    servo.set("Present_Position", 1234)
    assert _write(servo, "Present_Position", 99) == []
    assert servo.get("Present_Position") == 1234


def test_a_goal_is_clamped_into_the_position_limits() -> None:
    servo = ServoMemory(STS, 1)
    _write(servo, "Lock", 0)
    _write(servo, "Min_Position_Limit", 1000)
    _write(servo, "Max_Position_Limit", 3000)
    _write(servo, "Goal_Position", 3500)
    assert servo.get("Goal_Position") == 3000


def test_torque_enable_128_sets_the_middle() -> None:
    servo = ServoMemory(STS, 1)
    _write(servo, "Torque_Enable", 128)  # the encoder reads 2000 (see _write)
    assert servo.get("Homing_Offset") == 2000 - 2048 and servo.get("Torque_Enable") == 0


@given(st.integers(-2047, 2047))
def test_sign_magnitude_round_trips(value: int) -> None:
    raw = to_sign_magnitude(value, 11)
    assert 0 <= raw < 4096 and from_sign_magnitude(raw, 11) == value


def test_fault_bits_are_named() -> None:
    assert fault_text(0x20) == "overload"
    assert fault_text(0x05) == "input voltage out of range, over-temperature"
    assert "unknown" in fault_text(0x40)


@given(
    start=st.floats(0, 4095),
    goal=st.floats(0, 4095),
    speed=st.floats(100, 4000),
    acceleration=st.integers(0, 254),
)
def test_a_profile_reaches_its_goal_never_faster_than_its_speed(
    start: float, goal: float, speed: float, acceleration: int
) -> None:
    profile = ServoProfile(start)
    dt = 0.004
    previous = start
    for _ in range(30_000):  # 120 s: the slowest profile (100 steps/s²) takes ~45 s
        now = profile.follow(goal, dt, speed, acceleration)
        assert abs(now - previous) <= speed * dt + 1e-6
        if acceleration:
            assert abs(profile.speed) <= speed + 1e-6
        previous = now
        if now == goal:
            break
    assert profile.setpoint == pytest.approx(goal, abs=1e-9)


def test_an_accelerating_profile_starts_slowly() -> None:
    profile = ServoProfile(0.0)
    first = profile.follow(3000.0, 0.004, 3000.0, 10)  # 1000 steps/s²
    assert first == pytest.approx(1000 * 0.004 * 0.004)
    assert not math.isclose(first, 3000 * 0.004)
