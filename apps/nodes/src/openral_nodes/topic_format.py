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

from openral_nodes import topic_codec

MAX_ITEMS = 16
"""Sequences longer than this are summarised (numbers) or truncated (strings, messages)."""


def is_message(value: object) -> bool:
    """True for instances of generated ROS message classes."""
    return hasattr(value, "get_fields_and_field_types")


def format_message(msg: Any, *, max_items: int = MAX_ITEMS) -> str:
    """Multi-line, YAML-like text of ``msg``; a point cloud, a laser scan and a depth image
    start with a line that says what they hold (:func:`sensor_summary`)."""
    summary = sensor_summary(msg)
    lines = _lines(msg, 0, max_items)
    return "\n".join([f"# {summary}", *lines] if summary else lines)


def sensor_summary(msg: Any) -> str | None:
    """One line on a ``PointCloud2`` (point count, bounds), ``LaserScan`` (finite range span,
    beams without a return) or depth ``Image`` (range, pixels without a reading); None for
    any other message. A malformed one says so."""
    kind = type(msg).__name__ if type(msg).__module__.startswith("sensor_msgs.") else ""
    try:
        if kind == "PointCloud2":
            return _cloud_summary(topic_codec.cloud_points(msg))
        if kind == "LaserScan":
            return _scan_summary(np.asarray(msg.ranges, dtype=np.float64))
        if kind == "Image" and msg.encoding in topic_codec.DEPTH_ENCODINGS:
            return _depth_summary(topic_codec.depth_metres(msg))
    except topic_codec.ImageEncodingError as error:
        return str(error)
    return None


def _cloud_summary(points: np.ndarray[Any, Any]) -> str:
    finite = points[np.isfinite(points).all(axis=1)]
    if not len(finite):
        return f"{len(points)} points, none finite"
    low, high = finite.min(axis=0), finite.max(axis=0)
    bounds = ", ".join(
        f"{axis} [{format_value(float(a))}, {format_value(float(b))}]"
        for axis, a, b in zip("xyz", low, high, strict=True)
    )
    return f"{len(points)} points, {bounds} m"


def _span(label: str, values: np.ndarray[Any, Any], none: str) -> str:
    """``"<label> <min> to <max> m"`` of the finite ``values``, or ``none`` without one."""
    finite = values[np.isfinite(values)]
    if not finite.size:
        return none
    return f"{label} {format_value(float(finite.min()))} to {format_value(float(finite.max()))} m"


def _scan_summary(ranges: np.ndarray[Any, Any]) -> str:
    span = _span("range", ranges, "no finite range")
    far, near = int(np.sum(ranges == np.inf)), int(np.sum(ranges == -np.inf))
    return f"{ranges.size} beams, {span}, {far} without a return (+inf), {near} too close (-inf)"


def _depth_summary(depth: np.ndarray[Any, Any]) -> str:
    unseen = int(np.sum(~np.isfinite(depth)))
    height, width = depth.shape
    span = _span("depth", depth, "no reading")
    return f"{width}x{height} depth image, {span}, {unseen} pixels without one"


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
