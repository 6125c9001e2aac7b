"""A recorded rosbag2 bag in the browser view: its frame tree, joints and camera images.

A bag holds messages, not a model, so the view draws what the messages say:

- every frame of ``/tf_static`` and ``/tf`` as axes, along the tree the transforms form
  (``world/<root>/…/<child>``), static ones once and the others at their stamps;
- each ``sensor_msgs/JointState`` topic's positions on the ``joints`` plot, under the
  topic's name (``/joint_states`` and ``/openral/manifest_joint_states`` differ in units);
- each ``sensor_msgs/Image`` topic in rgb8, bgr8 or mono8 in a panel named after its
  camera (``/openral/cameras/<name>/image`` → ``<name>``), and depth images (32FC1 in
  metres, 16UC1 in millimetres, ``/openral/cameras/<name>/depth``) in that camera's panel,
  at their stamps.

Times are the messages' header stamps (simulated time for a deploy-sim recording). Other
topics are counted and left out. Reading is one pass per kind over the bag with rosbags;
memory stays at one message at a time.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from openral_sim.browser_view import BrowserView
from openral_sim.view_geometry import WORLD
from rosbags.rosbag2 import Reader

from openral_nodes.bag_writer import typestore

TF_TYPE = "tf2_msgs/msg/TFMessage"
JOINTS_TYPE = "sensor_msgs/msg/JointState"
IMAGE_TYPE = "sensor_msgs/msg/Image"
CHANNELS = {"rgb8": 3, "bgr8": 3, "mono8": 1}
"""Colour image encodings drawn, by channel count."""
DEPTH = {"32FC1": ("<f4", 1.0), "16UC1": ("<u2", 1e-3)}
"""Depth image encodings drawn: (dtype, metres per unit)."""


@dataclass
class BagContents:
    """What a bag holds for the view, and what it shows of it."""

    cameras: dict[str, str] = field(default_factory=dict)
    """Image topic → the camera name its panel shows."""
    frames: int = 0
    joint_states: int = 0
    images: int = 0
    skipped: dict[str, int] = field(default_factory=dict)
    """Topics left out → their message counts."""


def survey(bag: Path) -> BagContents:
    """The image topics of ``bag`` and the count of every topic the view leaves out."""
    contents = BagContents()
    with Reader(bag) as reader:
        for connection in reader.connections:
            if connection.msgtype == IMAGE_TYPE:
                match = re.fullmatch(r"/openral/cameras/([^/]+)/(image|depth)", connection.topic)
                name = match.group(1) if match else connection.topic.strip("/").replace("/", "_")
                contents.cameras[connection.topic] = name
            elif connection.msgtype not in (TF_TYPE, JOINTS_TYPE):
                skipped = contents.skipped.get(connection.topic, 0) + connection.msgcount
                contents.skipped[connection.topic] = skipped
    return contents


def show(bag: Path, view: BrowserView, contents: BagContents) -> None:
    """Send everything of ``bag`` the view draws (see the module doc) into ``view``."""
    parents = _tf_parents(bag)
    paths = _frame_paths(parents)
    for topic, msgtype, msg in _messages(bag):
        if msgtype == TF_TYPE:
            for transform in msg.transforms:
                contents.frames += _send_transform(view, paths, transform, topic == "/tf_static")
        elif msgtype == JOINTS_TYPE:
            positions = dict(zip(msg.name, np.asarray(msg.position).tolist(), strict=False))
            group = f"joints/{topic.strip('/').replace('/', '_')}"  # one line per topic
            view.plot(group, positions, _stamp_s(msg.header.stamp))
            contents.joint_states += 1
        elif msgtype == IMAGE_TYPE:
            _send_image(view, contents, topic, msg)


def _send_image(view: BrowserView, contents: BagContents, topic: str, msg: Any) -> None:
    camera, time_s = contents.cameras[topic], _stamp_s(msg.header.stamp)
    if msg.encoding in CHANNELS:
        view.image(camera, _pixels(msg), time_s)
    elif msg.encoding in DEPTH:
        dtype, scale = DEPTH[msg.encoding]
        rows = np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.step)
        values = rows[:, : msg.width * np.dtype(dtype).itemsize].copy().view(dtype)
        view.depth(camera, values.astype(np.float32) * scale, time_s)
    else:
        contents.skipped[topic] = contents.skipped.get(topic, 0) + 1
        return
    contents.images += 1


def _messages(bag: Path) -> Iterator[tuple[str, str, Any]]:
    """(topic, type, message) of every drawn topic, in the bag's time order."""
    types = typestore()
    with Reader(bag) as reader:
        wanted = [c for c in reader.connections if c.msgtype in (TF_TYPE, JOINTS_TYPE, IMAGE_TYPE)]
        for connection, _, raw in reader.messages(connections=wanted):
            msg = types.deserialize_cdr(raw, connection.msgtype)
            yield connection.topic, connection.msgtype, msg


def _tf_parents(bag: Path) -> dict[str, str]:
    """Child frame → parent frame, from every transform in the bag (the last one wins)."""
    parents: dict[str, str] = {}
    for _, msgtype, msg in _messages(bag):
        if msgtype == TF_TYPE:
            for transform in msg.transforms:
                parents[transform.child_frame_id] = transform.header.frame_id
    return parents


def _frame_paths(parents: dict[str, str]) -> dict[str, str]:
    """Frame → entity path along its parent chain under ``world`` (a root frame named
    ``world`` is the view's world itself; a loop is cut where it closes, so a malformed
    tree still draws)."""
    paths: dict[str, str] = {WORLD: WORLD} if WORLD not in parents else {}

    def path(frame: str, seen: frozenset[str]) -> str:
        if frame in paths:
            return paths[frame]
        parent = parents.get(frame)
        part = re.sub(r"[^A-Za-z0-9_-]", "_", frame) or "frame"
        above = path(parent, seen | {frame}) if parent and parent not in seen else WORLD
        paths[frame] = f"{above}/{part}"
        return paths[frame]

    for frame in sorted({*parents, *parents.values()}):
        path(frame, frozenset())
    return paths


def _send_transform(view: BrowserView, paths: dict[str, str], transform: Any, static: bool) -> int:
    t, q = transform.transform.translation, transform.transform.rotation
    time_s = None if static else _stamp_s(transform.header.stamp)
    view.transform(paths[transform.child_frame_id], (t.x, t.y, t.z), (q.x, q.y, q.z, q.w), time_s)
    return 1


def _pixels(msg: Any) -> np.ndarray:
    """An Image message's pixels as height x width (x 3) uint8, RGB order."""
    channels = CHANNELS[msg.encoding]
    rows = np.asarray(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)
    pixels = rows[:, : msg.width * channels].reshape(msg.height, msg.width, channels)
    if msg.encoding == "bgr8":
        pixels = pixels[..., ::-1]
    return pixels if channels == 3 else pixels[..., 0]


def _stamp_s(stamp: Any) -> float:
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)
