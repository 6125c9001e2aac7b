"""A ROS message from YAML values, as ``openral ros pub`` takes them.

``values`` is a YAML mapping (flow style fits one shell argument:
``'{linear: {x: 0.3}, angular: {z: 0.5}}'``) of field names to values; fields left out keep
their defaults. Each value must suit its field's type, read from the message class's own
introspection (``get_fields_and_field_types``): a number for a float field, a whole number
within range for an integer field, true/false for a boolean, text for a string, a mapping
for a nested message, a list for a sequence or array (of the right length for a fixed
array, at most the bound for a bounded sequence), each element checked the same way.

The text is read by the same guard as manifests (:mod:`openral_core.yaml_guard`: no
aliases, tags, deep nesting or huge documents) before ruamel loads it. Every mistake is one
line naming the field path and what it expected; nothing is published then.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from openral_core.errors import OpenralError, escaped
from openral_core.yaml_guard import scan_events
from ruamel.yaml import YAML

MAX_VALUES_BYTES = 64 * 1024
"""Longest values text accepted [bytes]."""
INTEGER_BITS = {"int8": 8, "int16": 16, "int32": 32, "int64": 64, "octet": 8, "char": 8}
INTEGER_BITS |= {f"u{name}": bits for name, bits in INTEGER_BITS.items() if name[0] == "i"}
FLOATS = frozenset({"float", "double"})
_ARRAY = re.compile(r"^(?P<item>.+)\[(?P<size>\d+)\]$")
_SEQUENCE = re.compile(r"^sequence<(?P<item>.+?)(?:, (?P<bound>\d+))?>$")
_WHERE = Path("<values>")


class MessageValueError(OpenralError):
    """Values that do not fit the message type."""


def parse_values(text: str) -> dict[str, Any]:
    """The mapping a values argument holds (``''`` is ``{}``).

    Raises:
        MessageValueError: Not YAML the guard accepts, or not a mapping.
    """
    if len(text.encode()) > MAX_VALUES_BYTES:
        raise MessageValueError(f"values: more than {MAX_VALUES_BYTES} bytes")
    if not text.strip():
        return {}
    try:
        scan_events(_WHERE, text)
    except OpenralError as error:
        raise MessageValueError(f"values: {str(error).removeprefix(str(_WHERE) + ':')}") from None
    document = YAML(typ="safe", pure=True).load(text)
    if not isinstance(document, dict):
        raise MessageValueError(f"values: expected a mapping of field names, got {escaped(text)}")
    return document


def build_message(cls: type[Any], values: Mapping[str, Any], path: str = "") -> Any:
    """An instance of ``cls`` with ``values`` set (see the module doc).

    Raises:
        MessageValueError: An unknown field, or a value that does not suit its field.
    """
    msg = cls()
    fields = msg.get_fields_and_field_types()
    for key, value in values.items():
        where = f"{path}{key}"
        if key not in fields:
            known = ", ".join(fields) or "(none)"
            raise MessageValueError(
                f"{escaped(str(where))}: not a field of {_type_name(cls)}; its fields: {known}"
            )
        setattr(msg, key, _value(fields[key], value, where, type(getattr(msg, key))))
    return msg


def _value(kind: str, value: Any, where: str, current: type[Any]) -> Any:
    """``value`` converted for a field of ROS type ``kind``."""
    array, sequence = _ARRAY.match(kind), _SEQUENCE.match(kind)
    if array or sequence:
        match = array or sequence
        assert match is not None
        return _items(match.group("item"), value, where, array, match)
    if kind in FLOATS:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _expected(where, "a number", value)
        return float(value)
    if kind in INTEGER_BITS:
        return _integer(kind, value, where)
    if kind == "boolean":
        if not isinstance(value, bool):
            raise _expected(where, "true or false", value)
        return value
    if kind in ("string", "wstring") or kind.startswith(("string<", "wstring<")):
        if not isinstance(value, str):
            raise _expected(where, "text", value)
        return value
    if not isinstance(value, Mapping):
        raise _expected(where, f"a mapping of {kind}'s fields", value)
    return build_message(current, value, f"{where}.")


def _items(item: str, value: Any, where: str, array: Any, match: re.Match[str]) -> list[Any]:
    if not isinstance(value, list):
        raise _expected(where, "a list", value)
    if array and len(value) != int(match.group("size")):
        raise _expected(where, f"a list of {match.group('size')} items", value)
    bound = None if array else match.group("bound")
    if bound is not None and len(value) > int(bound):
        raise _expected(where, f"a list of at most {bound} items", value)
    if "/" in item:
        raise MessageValueError(f"{escaped(where)}: lists of messages are not supported here")
    return [_value(item, v, f"{where}[{i}]", object) for i, v in enumerate(value)]


def _integer(kind: str, value: Any, where: str) -> int:
    bits, unsigned = INTEGER_BITS[kind], kind.startswith("u") or kind == "octet"
    low, high = (0, 2**bits - 1) if unsigned else (-(2 ** (bits - 1)), 2 ** (bits - 1) - 1)
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise _expected(where, f"a whole number from {low} to {high} ({kind})", value)
    return value


def _expected(where: str, what: str, value: Any) -> MessageValueError:
    shown = escaped(repr(value))
    return MessageValueError(f"{escaped(where)}: expected {what}, got {shown[:80]}")


def _type_name(cls: type[Any]) -> str:
    package = cls.__module__.split(".")[0]
    return f"{package}/msg/{cls.__name__}"
