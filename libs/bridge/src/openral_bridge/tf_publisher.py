"""TfPublisher: ``/tf`` and ``/tf_static`` of a simulated robot, from its frame tree.

- ``/tf_static`` (``tf2_msgs/TFMessage``, transient local, as tf2's static broadcaster
  publishes it): every static transform of the :class:`~openral_sim.frame_tree.FrameTree` in
  one message, at start and again after every reset (a reset may move a jittered camera,
  and puts the odometry frame where the base is);
- ``/tf`` (``tf2_msgs/TFMessage``): every dynamic transform, stamped with the simulated time
  of the state it shows, from a pacer job at the joint-state rate, and only when a tick has
  stepped the scene since the last one: a tf2 buffer refuses a transform whose stamp it
  already holds (``TF_REPEATED_DATA``), so none is sent twice.

The control loop copies the frames' world poses right after each tick, holding the HAL's
lock (:meth:`TfPublisher.capture`, one of its ``readers``); the transforms are computed and
the message filled in on the pacer's thread, in a message built once and updated in place.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np
from geometry_msgs.msg import TransformStamped
from openral_sim.frame_tree import FrameSample, FrameTree
from rclpy.qos import QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

from openral_bridge import ros_messages
from openral_bridge.paced_publishers import PacedPublishers
from openral_bridge.pacer import Pacer
from openral_bridge.topics import TF, TF_STATIC, TopicInfo

if TYPE_CHECKING:
    from rclpy.node import Node

    from openral_bridge.control_loop import ControlLoop

TF_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)  # type: ignore[no-untyped-call]
"""``/tf`` as tf2's broadcaster offers it."""
TF_STATIC_QOS = ros_messages.LATCHED
"""``/tf_static`` as tf2's static broadcaster offers it (a late listener gets it)."""


class TfPublisher:
    """The frames of one scene on ``/tf`` and ``/tf_static`` (see the module doc)."""

    def __init__(
        self,
        node: Node,
        tree: FrameTree,
        data: mujoco.MjData,
        rate_hz: float,
        leave_out: frozenset[str] = frozenset(),
        static: bool = True,
    ) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the publishers.
            tree: The scene's frame tree.
            data: The scene's live data (read only by :meth:`capture`).
            rate_hz: Highest ``/tf`` rate [Hz] (the joint-state rate).
            leave_out: Frames whose transform another node publishes (``--no-tf``: those a
                robot_state_publisher takes from the URDF).
            static: False sends no static transform at all (``--no-static-tf``).
        """
        self.node, self.tree, self.data, self.rate_hz = node, tree, data, float(rate_hz)
        names = tree.frames
        kept = tree.static if static else ()
        self.static = np.array([r for r in kept if names[r].name not in leave_out], np.intp)
        """Rows of the static transforms sent."""
        self.dynamic = np.array(
            [r for r in tree.dynamic if names[r].name not in leave_out], np.intp
        )
        """Rows of the dynamic transforms sent."""
        self.published = 0
        """``/tf`` messages sent since :meth:`start`."""
        self._latest: FrameSample | None = None
        self._sent: FrameSample | None = None
        self._out = PacedPublishers(node)
        self._tick_hz = self.rate_hz
        self._dynamic = _message(tree, self.dynamic)
        self._static = _message(tree, self.static)

    def capture(self) -> None:
        """Copy every frame's world pose (the control loop calls it holding the HAL's lock)."""
        self._latest = self.tree.sample(self.data)

    def start(self, pacer: Pacer, loop: ControlLoop) -> None:
        """Capture after every tick of ``loop``, publish the static transforms and the
        dynamic ones once now, then ``/tf`` at :attr:`rate_hz` on ``pacer`` (after every tick
        when that is as often)."""
        self.stop()
        node = self.node
        self._out.open(
            node.create_publisher(TFMessage, TF, TF_QOS),
            node.create_publisher(TFMessage, TF_STATIC, TF_STATIC_QOS),
        )
        loop.add_reader(self.capture)
        self._tick_hz = 1.0 / loop.tick_period_s
        self.publish_static()
        self.publish()
        self._out.schedule(pacer, 1.0 / self.rate_hz, self.publish, "tf", loop)

    def stop(self) -> None:
        """Unschedule the job and destroy the publishers (idempotent)."""
        self._out.close()
        self._sent = None

    def publish(self) -> None:
        """Send the dynamic transforms of the newest capture, unless already sent."""
        sample, publishers = self._latest, self._out.publishers
        if sample is None or not publishers or sample is self._sent or not len(self.dynamic):
            return
        _fill(self._dynamic, sample, self.tree, self.dynamic)
        publishers[0].publish(self._dynamic)
        self._sent = sample
        self.published += 1

    def publish_static(self) -> None:
        """Send every static transform of the newest capture (after start and each reset)."""
        sample, publishers = self._latest, self._out.publishers
        if sample is not None and publishers:
            _fill(self._static, sample, self.tree, self.static)
            publishers[1].publish(self._static)

    def topics(self) -> list[TopicInfo]:
        """``/tf`` (a new pose at most once per control tick, so at the joint-state rate or the
        control rate, whichever is lower) and ``/tf_static`` (latched)."""
        kind = "tf2_msgs/msg/TFMessage"
        return [
            TopicInfo(TF, kind, min(self.rate_hz, self._tick_hz)),
            TopicInfo(TF_STATIC, kind, None),
        ]


def _message(tree: FrameTree, rows: Any) -> Any:
    """A TFMessage with one transform per frame of ``rows`` (names set, values zero)."""
    transforms = []
    for row in rows:
        frame = tree.frames[int(row)]
        transform = TransformStamped()
        transform.header.frame_id = frame.parent
        transform.child_frame_id = frame.name
        transforms.append(transform)
    return TFMessage(transforms=transforms)


def _fill(message: Any, sample: FrameSample, tree: FrameTree, rows: Any) -> None:
    """Set each transform of ``message`` (built by :func:`_message` for ``rows``)."""
    if not len(rows):
        return
    positions, quats = sample.relative(tree, np.asarray(rows, dtype=np.intp))
    stamp = ros_messages.stamp(sample.sim_time_s)
    rows_of = zip(message.transforms, positions.tolist(), quats.tolist(), strict=True)
    for transform, position, quat in rows_of:
        transform.header.stamp = stamp
        translation, rotation = transform.transform.translation, transform.transform.rotation
        translation.x, translation.y, translation.z = position
        rotation.w, rotation.x, rotation.y, rotation.z = quat
