"""The serial servos a ``real`` section can name: their control tables as data.

Feetech's STS/SMS memory map (the register names LeRobot uses, from Feetech's manual):
each register is an (address, size in bytes) pair; a few hold sign-magnitude numbers whose
sign is one bit. The driver reads the addresses from a robot's generated tables
(:mod:`openral_core.real_wiring`), the bus emulator lays its servos' memory out from here,
and the manifest's ``settings`` names are checked against it by the schema.
"""

from __future__ import annotations

from dataclasses import dataclass

Register = tuple[int, int]
"""(address, size in bytes) of one register."""

STS_REGISTERS: dict[str, Register] = {
    # EEPROM (kept over a power cycle; written only with Lock 0)
    "Firmware_Major_Version": (0, 1),
    "Firmware_Minor_Version": (1, 1),
    "Model_Number": (3, 2),
    "ID": (5, 1),
    "Baud_Rate": (6, 1),
    "Return_Delay_Time": (7, 1),
    "Response_Status_Level": (8, 1),
    "Min_Position_Limit": (9, 2),
    "Max_Position_Limit": (11, 2),
    "Max_Temperature_Limit": (13, 1),
    "Max_Voltage_Limit": (14, 1),
    "Min_Voltage_Limit": (15, 1),
    "Max_Torque_Limit": (16, 2),
    "Phase": (18, 1),
    "Unloading_Condition": (19, 1),
    "LED_Alarm_Condition": (20, 1),
    "P_Coefficient": (21, 1),
    "D_Coefficient": (22, 1),
    "I_Coefficient": (23, 1),
    "Minimum_Startup_Force": (24, 2),
    "CW_Dead_Zone": (26, 1),
    "CCW_Dead_Zone": (27, 1),
    "Protection_Current": (28, 2),
    "Angular_Resolution": (30, 1),
    "Homing_Offset": (31, 2),
    "Operating_Mode": (33, 1),
    "Protective_Torque": (34, 1),
    "Protection_Time": (35, 1),
    "Overload_Torque": (36, 1),
    # SRAM (lost at power off)
    "Torque_Enable": (40, 1),
    "Acceleration": (41, 1),
    "Goal_Position": (42, 2),
    "Goal_Time": (44, 2),
    "Goal_Velocity": (46, 2),
    "Torque_Limit": (48, 2),
    "Lock": (55, 1),
    "Present_Position": (56, 2),
    "Present_Velocity": (58, 2),
    "Present_Load": (60, 2),
    "Present_Voltage": (62, 1),
    "Present_Temperature": (63, 1),
    "Status": (65, 1),
    "Moving": (66, 1),
    "Present_Current": (69, 2),
}
"""The STS/SMS series control table."""

STS_SIGN_BITS: dict[str, int] = {
    "Homing_Offset": 11,
    "Goal_Velocity": 15,
    "Present_Velocity": 15,
    "Present_Load": 10,
}
"""Registers holding sign-magnitude numbers, and the bit that carries the sign."""

STS_FAULT_BITS: dict[int, str] = {
    0x01: "input voltage out of range",
    0x02: "angle sensor fault",
    0x04: "over-temperature",
    0x08: "over-current",
    0x20: "overload",
}
"""Bits of a status packet's error byte (and of the Status register) and what each means."""


@dataclass(frozen=True)
class ServoModel:
    """One servo model: what identifies it on the bus and how its positions count."""

    name: str
    model_number: int
    """What the servo answers at Model_Number (a ping's reply)."""
    resolution: int
    """Position steps per turn."""
    max_speed_steps_s: float
    """No-load speed at the nominal voltage [steps/s] (what an emulated servo moves at)."""
    registers: dict[str, Register]
    sign_bits: dict[str, int]


SERVO_MODELS: dict[str, ServoModel] = {
    "sts3215": ServoModel("sts3215", 777, 4096, 3073.0, STS_REGISTERS, STS_SIGN_BITS),
    "sts3250": ServoModel("sts3250", 2825, 4096, 3073.0, STS_REGISTERS, STS_SIGN_BITS),
}
"""Every servo model the schema's ``servo_model`` offers, by name. The no-load speed is
Feetech's figure for the STS3215, 0.222 s per 60 degrees: 3073 steps/s."""


def fault_text(bits: int) -> str:
    """The faults an error byte (or Status register) reports, in words ("" for none)."""
    known = [text for bit, text in STS_FAULT_BITS.items() if bits & bit]
    unknown = bits & ~sum(STS_FAULT_BITS) & 0x7F
    if unknown:
        known.append(f"unknown fault bits 0x{unknown:02x}")
    return ", ".join(known)
