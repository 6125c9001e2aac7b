"""Text of ``openral ros tf``: the frame tree, or one composed transform.

The listening itself is :mod:`openral_nodes.tf_listener`; this module turns its buffer into
the lines the command prints (frame names escaped: they come from peers).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from openral_core.errors import OpenralError, escaped

if TYPE_CHECKING:
    from openral_nodes.tf_listener import Link, Lookup, TfBuffer
    from rclpy.node import Node

POLL_S = 0.05
"""Interval between checks of what has arrived [s]."""
LATE_DISCOVERY_S = 3.0
"""How much longer than the listening time the first transform is awaited: FastDDS
announces a participant again every 3 s, so a peer that missed the first announcement (a
loaded machine) shows up within that [s]."""


def gather(node: Node, timeout_s: float, frame: str | None, target: str | None) -> TfBuffer:
    """A buffer fed by ``/tf`` and ``/tf_static`` for ``timeout_s`` [s] from the first
    transform on (which is awaited ``timeout_s + LATE_DISCOVERY_S``); ``node`` is spun by the
    caller. With both ``frame`` and ``target`` named it returns as soon as the transform
    between them resolves; otherwise it listens the whole time, so every frame and its rate
    are seen and the root is not mistaken for a frame below it."""
    from openral_nodes.tf_listener import TfBuffer, listen

    buffer = TfBuffer()
    listen(node, buffer)
    start = time.monotonic()
    first: float | None = None
    while True:
        now = time.monotonic()
        if first is None and buffer.links:
            first = now
        if now - (start + LATE_DISCOVERY_S if first is None else first) >= timeout_s:
            return buffer
        if frame is not None and target is not None and _resolves(buffer, target, frame):
            return buffer
        time.sleep(POLL_S)


def report(
    buffer: TfBuffer, frame: str | None, target: str | None, timeout_s: float, domain_id: int
) -> list[str]:
    """What ``ros tf`` prints: the tree without ``frame``, else ``frame``'s pose in
    ``target`` (default: the root).

    Raises:
        OpenralError: No transform arrived (``timeout_s`` was the listening time).
        FrameNotFound, NoTransformPath: ``frame`` or ``target`` is unknown, or unreachable.
    """
    if not buffer.links:
        dropped = f" ({buffer.rejected} dropped as invalid)" if buffer.rejected else ""
        raise OpenralError(
            f"no transforms on /tf or /tf_static{dropped} within "
            f"{timeout_s + LATE_DISCOVERY_S:g} s on ROS_DOMAIN_ID={domain_id}"
        )
    if frame is None:
        return tree_lines(buffer)
    return transform_lines(buffer.lookup(target or buffer.root() or "", frame))


def _resolves(buffer: TfBuffer, target: str, frame: str) -> bool:
    try:
        buffer.lookup(target, frame)
    except OpenralError:
        return False
    return True


def tree_lines(buffer: TfBuffer) -> list[str]:
    """The main root's tree, one frame a line (indented below its parent: name, ``static``
    or its rate, its parent), then the frames with no path to the root and the transforms
    dropped, if any."""
    rows, unrooted = buffer.tree()
    names = [f"{'  ' * row.depth}{escaped(row.frame)}" for row in rows]
    width = max(map(len, names), default=0)
    kinds = [_kind(row.link) for row in rows]
    kind_width = max(map(len, kinds), default=0)
    lines = [
        f"{name:<{width}}  {kind:<{kind_width}}  parent {escaped(row.link.parent)}"
        if row.link
        else f"{name:<{width}}  root"
        for name, kind, row in zip(names, kinds, rows, strict=True)
    ]
    if unrooted:
        root = escaped(rows[0].frame) if rows else "a root"
        lost = [f"{escaped(f)}{_parent_note(buffer.links.get(f))}" for f in unrooted]
        lines.append(f"no path to {root}: {', '.join(lost)}")
    if buffer.rejected:
        lines.append(
            f"{buffer.rejected} transform(s) dropped: an empty or self-parented frame, "
            "a number that is not finite or a zero quaternion"
        )
    return [line.rstrip() for line in lines]


def _kind(link: Link | None) -> str:
    if link is None:
        return ""
    if link.static:
        return "static"
    rate = link.rate_hz
    return "seen once" if rate is None else f"{rate:.1f} Hz"


def _parent_note(link: Link | None) -> str:
    return " (no parent)" if link is None else f" (parent {escaped(link.parent)})"


def transform_lines(lookup: Lookup) -> list[str]:
    """``source``'s pose in ``target``: translation [m], quaternion, roll/pitch/yaw [rad],
    stamp [s]."""
    pose = lookup.transform
    return [
        f"{escaped(lookup.target)} -> {escaped(lookup.source)}",
        f"translation [m]: {_numbers(pose.translation)}",
        f"rotation (x y z w): {_numbers(pose.rotation)}",
        f"roll pitch yaw [rad]: {_numbers(pose.rpy())}",
        f"stamp [s]: {lookup.stamp_s:.6f}",
    ]


def _numbers(values: tuple[float, ...]) -> str:
    return " ".join(f"{round(v, 9) + 0.0:.9f}".rstrip("0").rstrip(".") for v in values)
