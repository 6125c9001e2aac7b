"""A small TF buffer of our own (tf2_ros is not on PyPI): the latest transform of each
frame from ``/tf`` and ``/tf_static``, composed along the frame tree.

Each transform ``parent → child`` maps points in the child frame to the parent frame
(``p_parent = T * p_child``), as a ``geometry_msgs/TransformStamped`` does. The buffer keeps
the latest one per child frame; :meth:`TfBuffer.lookup` composes the chain through the two
frames' common ancestor. Everything but :func:`listen` is plain Python (no rclpy), so the
composition is tested without a graph.

Example::

    buffer = TfBuffer()
    buffer.set_transform("world", "base", Transform((0.0, 0.0, 0.5)), stamp_s=0.0, static=True)
    pose = buffer.lookup("world", "base")  # base's pose in world
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from openral_core.errors import OpenralError, did_you_mean, escaped

if TYPE_CHECKING:
    from rclpy.node import Node

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]
"""A unit quaternion ``(x, y, z, w)``."""
TF_DEPTH = 100
"""Queue depth of both subscriptions (tf2_ros's own)."""


class FrameNotFound(OpenralError):
    """A frame no transform names; suggests the closest known frames."""


class NoTransformPath(OpenralError):
    """Two known frames whose trees do not meet."""


@dataclass(frozen=True)
class Transform:
    """A rigid transform: ``translation`` [m], then ``rotation`` (unit quaternion x, y, z, w)."""

    translation: Vector = (0.0, 0.0, 0.0)
    rotation: Quaternion = (0.0, 0.0, 0.0, 1.0)

    def __mul__(self, other: Transform) -> Transform:
        """``self ∘ other``: apply ``other`` first (``T_a_c = T_a_b * T_b_c``)."""
        moved = _rotate(self.rotation, other.translation)
        return Transform(
            (
                self.translation[0] + moved[0],
                self.translation[1] + moved[1],
                self.translation[2] + moved[2],
            ),
            _normalised(_product(self.rotation, other.rotation)),
        )

    def inverse(self) -> Transform:
        """The transform that undoes this one."""
        x, y, z, w = self.rotation
        conjugate = (-x, -y, -z, w)
        t = _rotate(conjugate, self.translation)
        return Transform((-t[0], -t[1], -t[2]), conjugate)

    def rpy(self) -> Vector:
        """Roll, pitch, yaw [rad] of the rotation (``R = Rz(yaw) Ry(pitch) Rx(roll)``)."""
        x, y, z, w = self.rotation
        roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
        pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
        yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        return roll, pitch, yaw


def _product(a: Quaternion, b: Quaternion) -> Quaternion:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _rotate(q: Quaternion, v: Vector) -> Vector:
    """``v`` rotated by ``q``: ``v + 2 w c + 2 u x c`` with ``c = u x v``, ``u`` = q's
    vector part."""
    x, y, z, w = q
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    dx, dy, dz = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return v[0] + 2 * (w * cx + dx), v[1] + 2 * (w * cy + dy), v[2] + 2 * (w * cz + dz)


def _normalised(q: Quaternion) -> Quaternion:
    norm = math.sqrt(sum(c * c for c in q))
    return (q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm)


@dataclass
class Link:
    """The latest transform of one child frame, and how often it arrived."""

    parent: str
    transform: Transform
    stamp_s: float
    static: bool
    count: int = 1
    first_seen_s: float = 0.0
    last_seen_s: float = 0.0

    @property
    def rate_hz(self) -> float | None:
        """Arrival rate [Hz] over the listening time, None when static or seen once."""
        span = self.last_seen_s - self.first_seen_s
        return None if self.static or self.count < 2 or span <= 0 else (self.count - 1) / span


@dataclass(frozen=True)
class Lookup:
    """A composed transform: ``source``'s pose in ``target`` and the chain's stamp [s]
    (the oldest dynamic stamp, as tf2's latest common time; the newest static one when
    every link is static)."""

    target: str
    source: str
    transform: Transform
    stamp_s: float


@dataclass(frozen=True)
class TreeRow:
    """One frame of :meth:`TfBuffer.tree`: its depth below the root and its link (None for
    the root)."""

    depth: int
    frame: str
    link: Link | None


@dataclass
class TfBuffer:
    """The latest transform per child frame; thread-safe (fed by subscription callbacks)."""

    links: dict[str, Link] = field(default_factory=dict)
    rejected: int = 0
    """Transforms dropped: empty or self-parented frames, non-finite numbers, a zero quaternion."""
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def set_transform(
        self,
        parent: str,
        child: str,
        transform: Transform,
        stamp_s: float,
        *,
        static: bool,
        seen_s: float = 0.0,
    ) -> None:
        """Record ``parent → child`` (seen at monotonic time ``seen_s`` [s])."""
        parent, child = parent.lstrip("/"), child.lstrip("/")
        numbers = (*transform.translation, *transform.rotation, stamp_s)
        norm = math.sqrt(sum(c * c for c in transform.rotation))
        valid = parent and child and parent != child and all(map(math.isfinite, numbers))
        with self._lock:
            if not valid or norm < 1e-9:  # a zero quaternion is no rotation to normalise
                self.rejected += 1
                return
            unit = Transform(transform.translation, _normalised(transform.rotation))
            old = self.links.get(child)
            count, first = (old.count + 1, old.first_seen_s) if old else (1, seen_s)
            self.links[child] = Link(parent, unit, stamp_s, static, count, first, seen_s)

    def add_message(self, msg: Any, *, static: bool, seen_s: float) -> None:
        """Record every transform of a ``tf2_msgs/TFMessage`` (read by field name)."""
        for item in msg.transforms:
            t, r, stamp = item.transform.translation, item.transform.rotation, item.header.stamp
            self.set_transform(
                item.header.frame_id,
                item.child_frame_id,
                Transform((t.x, t.y, t.z), (r.x, r.y, r.z, r.w)),
                stamp.sec + stamp.nanosec * 1e-9,
                static=static,
                seen_s=seen_s,
            )

    def frames(self) -> list[str]:
        """Every frame named as a parent or a child, sorted."""
        with self._lock:
            return sorted({*self.links, *(link.parent for link in self.links.values())})

    def root(self) -> str | None:
        """The main root: ``world`` when it has no parent, else the parentless frame with
        the most frames below it (ties by name); None for an empty buffer."""
        with self._lock:
            links = dict(self.links)
        tops = sorted({link.parent for link in links.values()} - set(links))
        if "world" in tops:
            return "world"
        sizes = {top: sum(1 for _ in _below(links, top)) for top in tops}
        return min(tops, key=lambda top: (-sizes[top], top), default=None)

    def lookup(self, target: str, source: str) -> Lookup:
        """``source``'s pose in ``target`` (maps ``source`` points into ``target``).

        Raises:
            FrameNotFound: ``target`` or ``source`` is in no transform.
            NoTransformPath: Their chains share no frame.
        """
        target, source = target.lstrip("/"), source.lstrip("/")  # tf2 drops a leading slash
        known = self.frames()
        for frame in (target, source):
            if frame not in known:
                raise FrameNotFound(
                    f"unknown frame {escaped(frame)}{escaped(_suggestion(frame, known))}; "
                    f"{len(known)} frames known"
                )
        with self._lock:
            links = dict(self.links)
        up_source, up_target = _ancestors(links, source), _ancestors(links, target)
        common = next((frame for frame in up_source if frame in up_target), None)
        if common is None:
            raise NoTransformPath(
                f"no transform path from {escaped(target)} to {escaped(source)}: "
                f"{escaped(source)} hangs below {escaped(up_source[-1])}, "
                f"{escaped(target)} below {escaped(up_target[-1])}"
            )
        chain_s = up_source[: up_source.index(common)]
        chain_t = up_target[: up_target.index(common)]
        pose = _compose(links, chain_t).inverse() * _compose(links, chain_s)
        return Lookup(target, source, pose, _stamp([links[f] for f in chain_s + chain_t]))

    def tree(self) -> tuple[list[TreeRow], list[str]]:
        """The main root's tree, parents before children (siblings by name), and the
        frames with no path to that root, sorted."""
        root = self.root()
        with self._lock:
            links = dict(self.links)
        rows = []
        if root is not None:
            rows = [TreeRow(0, root, None)]
            rows += [TreeRow(depth, frame, links[frame]) for depth, frame in _below(links, root)]
        placed = {row.frame for row in rows}
        return rows, sorted({*links, *(link.parent for link in links.values())} - placed)


def _suggestion(frame: str, known: list[str]) -> str:
    """`` (did you mean …?)``: the known frames that are ``frame`` with or without a prefix
    (``panda_hand`` → ``hand``, ``link7`` → ``panda_link7``), else the closest spellings."""
    same = [k for k in known if frame.endswith(f"_{k}") or k.endswith(f"_{frame}")][:3]
    if not same:
        return did_you_mean(frame, known)
    names = same[0] if len(same) == 1 else f"{', '.join(same[:-1])} or {same[-1]}"
    return f" (did you mean {names}?)"


def _ancestors(links: dict[str, Link], frame: str) -> list[str]:
    """``frame``, its parent, grandparent… up to a frame with no parent (a loop ends it)."""
    chain, seen = [frame], {frame}
    while (link := links.get(chain[-1])) is not None and link.parent not in seen:
        chain.append(link.parent)
        seen.add(link.parent)
    return chain


def _compose(links: dict[str, Link], chain: list[str]) -> Transform:
    """The pose of ``chain[0]`` in the parent of ``chain[-1]`` (identity for no chain)."""
    pose = Transform()
    for frame in chain:
        pose = links[frame].transform * pose
    return pose


def _stamp(used: list[Link]) -> float:
    dynamic = [link.stamp_s for link in used if not link.static]
    if dynamic:
        return min(dynamic)
    return max((link.stamp_s for link in used), default=0.0)


def _below(links: dict[str, Link], root: str) -> Iterator[tuple[int, str]]:
    """``(depth, frame)`` of every frame below ``root``, depth first, siblings by name."""
    children: dict[str, list[str]] = {}
    for child, link in sorted(links.items()):
        children.setdefault(link.parent, []).append(child)
    stack = [(1, child) for child in reversed(children.get(root, []))]
    seen = {root}
    while stack:
        depth, frame = stack.pop()
        if frame in seen:
            continue
        seen.add(frame)
        yield depth, frame
        stack.extend((depth + 1, child) for child in reversed(children.get(frame, [])))


def listen(node: Node, buffer: TfBuffer) -> Iterable[Any]:
    """Subscribe ``node`` to ``/tf`` (volatile) and ``/tf_static`` (transient local, so the
    static transforms published before we came arrive too), feeding ``buffer``; returns the
    subscriptions (destroy them, or the node, to stop)."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from tf2_msgs.msg import TFMessage

    def qos(durability: DurabilityPolicy) -> QoSProfile:
        return QoSProfile(  # type: ignore[no-untyped-call]
            depth=TF_DEPTH, durability=durability, reliability=ReliabilityPolicy.RELIABLE
        )

    return [
        node.create_subscription(
            TFMessage,
            topic,
            _feed(buffer, static=static),
            qos(DurabilityPolicy.TRANSIENT_LOCAL if static else DurabilityPolicy.VOLATILE),
        )
        for topic, static in (("/tf", False), ("/tf_static", True))
    ]


def _feed(buffer: TfBuffer, *, static: bool) -> Callable[[Any], None]:
    """A subscription callback recording each message's transforms in ``buffer``."""

    def record(msg: Any) -> None:
        buffer.add_message(msg, static=static, seen_s=time.monotonic())

    return record
