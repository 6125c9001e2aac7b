"""The control table of one emulated STS servo, and the rules its registers follow.

A write a real servo would not keep is not kept here either: read-only registers (model
number, present values, status) ignore writes, EEPROM registers (below Torque_Enable) keep
a write only while Lock is 0, and a goal outside Min/Max_Position_Limit is clamped to them.
Writing 128 to Torque_Enable makes the present position read 2048 (the servo's own
"middle" calibration). Numbers flagged by the model's sign bits are sign-magnitude.
"""

from __future__ import annotations

from openral_core.servo_models import ServoModel

MEMORY_SIZE = 256
"""Bytes of control table an emulated servo answers reads from."""
EEPROM_END = 40
"""First address of the SRAM area (Torque_Enable); everything below is EEPROM."""
READ_ONLY = frozenset(
    {
        "Firmware_Major_Version",
        "Firmware_Minor_Version",
        "Model_Number",
        "Present_Position",
        "Present_Velocity",
        "Present_Load",
        "Present_Voltage",
        "Present_Temperature",
        "Status",
        "Moving",
        "Present_Current",
    }
)
SET_MIDDLE = 128
"""Torque_Enable value that recalibrates the servo so its present position reads 2048."""
FACTORY = {
    "Firmware_Major_Version": 3,
    "Firmware_Minor_Version": 10,
    "Return_Delay_Time": 250,
    "Response_Status_Level": 1,
    "Min_Position_Limit": 0,
    "Max_Position_Limit": 4095,
    "Max_Temperature_Limit": 70,
    "Max_Voltage_Limit": 140,
    "Min_Voltage_Limit": 40,
    "Max_Torque_Limit": 1000,
    "P_Coefficient": 32,
    "D_Coefficient": 32,
    "I_Coefficient": 0,
    "Protection_Current": 500,
    "Overload_Torque": 80,
    "Torque_Limit": 1000,
    "Lock": 1,
    "Present_Voltage": 120,
    "Present_Temperature": 30,
}
"""Factory values (the rest is 0): a 12 V STS3215 as it leaves the box."""


def to_sign_magnitude(value: int, sign_bit: int) -> int:
    """``value`` with its sign in bit ``sign_bit`` and its magnitude below it."""
    magnitude = min(abs(int(value)), (1 << sign_bit) - 1)
    return magnitude | (1 << sign_bit) if value < 0 else magnitude


def from_sign_magnitude(raw: int, sign_bit: int) -> int:
    """The signed number a sign-magnitude register holds."""
    magnitude = raw & ((1 << sign_bit) - 1)
    return -magnitude if raw & (1 << sign_bit) else magnitude


class ServoMemory:
    """One servo's control table (see the module doc)."""

    def __init__(self, model: ServoModel, servo_id: int) -> None:
        """A servo fresh from the factory, answering at ``servo_id``."""
        self.model = model
        self.data = bytearray(MEMORY_SIZE)
        self._names = {address: name for name, (address, _) in model.registers.items()}
        self.set("Model_Number", model.model_number)
        self.set("ID", servo_id)
        for name, value in FACTORY.items():
            self.set(name, value)

    # -- typed access (the emulator's side) ------------------------------------------------

    def get(self, name: str) -> int:
        """Register ``name`` as a number (signed where the model says so)."""
        address, size = self.model.registers[name]
        raw = int.from_bytes(self.data[address : address + size], "little")
        sign_bit = self.model.sign_bits.get(name)
        return raw if sign_bit is None else from_sign_magnitude(raw, sign_bit)

    def set(self, name: str, value: int) -> None:
        """Store ``value`` in register ``name`` whatever its access (the servo's own
        updates: present values, status)."""
        address, size = self.model.registers[name]
        sign_bit = self.model.sign_bits.get(name)
        raw = int(value) if sign_bit is None else to_sign_magnitude(int(value), sign_bit)
        self.data[address : address + size] = (raw & ((1 << (8 * size)) - 1)).to_bytes(
            size, "little"
        )

    # -- the bus's side ----------------------------------------------------------------------

    def read(self, address: int, length: int) -> bytes:
        """``length`` bytes from ``address`` (past the table's end: zeros)."""
        chunk = bytes(self.data[address : address + length])
        return chunk + bytes(length - len(chunk))

    def write(self, address: int, payload: bytes, raw_position: int) -> list[str]:
        """A WRITE from the bus: keep what a servo keeps.

        Args:
            address: First address written.
            payload: The bytes written.
            raw_position: The encoder's reading now (for Torque_Enable 128).

        Returns:
            The registers that changed (by name, once each).
        """
        changed: list[str] = []
        for offset, value in enumerate(payload):
            target = address + offset
            if target >= MEMORY_SIZE or not self._writable(target):
                continue
            if self.data[target] != value:
                self.data[target] = value
                name = self._register_at(target)
                if name is not None and name not in changed:
                    changed.append(name)
        if "Torque_Enable" in changed and self.get("Torque_Enable") == SET_MIDDLE:
            self.set("Homing_Offset", raw_position - 2048)
            self.set("Torque_Enable", 0)
        if "Goal_Position" in changed:
            self.set("Goal_Position", self.clamped_goal(self.get("Goal_Position")))
        return changed

    def clamped_goal(self, goal: int) -> int:
        """``goal`` inside Min/Max_Position_Limit (both 0: no limits)."""
        low, high = self.get("Min_Position_Limit"), self.get("Max_Position_Limit")
        if low == 0 and high == 0:
            return goal
        return min(max(goal, low), high)

    def _writable(self, address: int) -> bool:
        name = self._register_at(address)
        if name in READ_ONLY:
            return False
        return address >= EEPROM_END or self.get("Lock") == 0

    def _register_at(self, address: int) -> str | None:
        """The register whose bytes include ``address`` (None: a gap in the table)."""
        for start in (address, address - 1):
            name = self._names.get(start)
            if name is not None and start + self.model.registers[name][1] > address:
                return name
        return None
