"""Render any ROS message as indented ``field: value`` text, summarising big arrays.

Works from the generated message classes' own introspection
(``get_fields_and_field_types``), so every type importable in the environment is covered.
"""

from __future__ import annotations

import array
from collections.abc import Sequence
from typing import Any

import numpy as np
from openral_core.errors import escaped

MAX_ITEMS = 16
"""Sequences longer than this are summarised (numbers) or truncated (strings, messages)."""


def is_message(value: object) -> bool:
    """True for instances of generated ROS message classes."""
    return hasattr(value, "get_fields_and_field_types")


def format_message(msg: Any, *, max_items: int = MAX_ITEMS) -> str:
    """Multi-line, YAML-like text of ``msg``."""
    return "\n".join(_lines(msg, 0, max_items))


def _lines(msg: Any, indent: int, max_items: int) -> list[str]:
    pad = "  " * indent
    lines: list[str] = []
    for field in msg.get_fields_and_field_types():
        value = getattr(msg, field)
        if is_message(value):
            lines.append(f"{pad}{field}:")
            lines.extend(_lines(value, indent + 1, max_items))
        elif _is_sequence(value) and len(value) and is_message(value[0]):
            lines.append(f"{pad}{field}:")
            for item in list(value)[:max_items]:
                body = _lines(item, indent + 1, max_items)
                lines.append(f"{pad}- {body[0].lstrip()}" if body else f"{pad}- {{}}")
                lines.extend(body[1:])
            if len(value) > max_items:
                lines.append(f"{pad}- … ({len(value) - max_items} more)")
        else:
            lines.append(f"{pad}{field}: {format_value(value, max_items)}")
    return lines


def _is_sequence(value: object) -> bool:
    return isinstance(value, list | tuple | array.array | np.ndarray | bytes)


def format_value(value: object, max_items: int = MAX_ITEMS) -> str:
    """One-line text of a scalar or a sequence of scalars."""
    if isinstance(value, str):
        return escaped(value) if value else "''"  # a peer's escape codes never reach a tty
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float | np.floating):
        text = f"{float(value):.6g}"
        return text if any(c in text for c in ".enai") else f"{text}.0"
    if isinstance(value, bytes | array.array | np.ndarray) or (
        isinstance(value, list | tuple) and all(_is_number(v) for v in value)
    ):
        numbers = np.frombuffer(value, np.uint8) if isinstance(value, bytes) else np.asarray(value)
        return _numbers(numbers, max_items)
    if isinstance(value, list | tuple):
        return _short_list([format_value(v, max_items) for v in value], max_items)
    return str(value)


def _is_number(value: object) -> bool:
    return isinstance(value, int | float | np.number) and not isinstance(value, bool)


def _numbers(values: np.ndarray[Any, Any], max_items: int) -> str:
    flat = values.ravel()
    if flat.size <= max_items:
        return _short_list([format_value(v.item()) for v in flat], max_items)
    return (
        f"<{flat.size} values {flat.dtype}: min {format_value(flat.min().item())}, "
        f"max {format_value(flat.max().item())}, mean {format_value(float(flat.mean()))}>"
    )


def _short_list(items: Sequence[str], max_items: int) -> str:
    shown = ", ".join(items[:max_items])
    more = f", … ({len(items)} total)" if len(items) > max_items else ""
    return f"[{shown}{more}]"
