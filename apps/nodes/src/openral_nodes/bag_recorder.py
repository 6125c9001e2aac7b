"""Record a live ROS 2 graph into a rosbag2 bag: ``openral ros record`` and
``openral deploy sim --record``.

Every topic the node sees (or those named), hidden ones (``/_action/...``) left out as
``ros2 bag record`` leaves them, is subscribed to in raw form: the callback gets the bytes the
publisher serialised and passes them, stamped with the receive time, to a
:class:`~openral_nodes.bag_writer.BagWriter` (nothing is deserialised). The graph is looked
at again every :data:`DISCOVERY_S`, so topics that appear later are recorded from then on.
The subscription asks for the best QoS the publishers offer (a latched ``/tf_static`` or
``/robot_description`` arrives whole), and the bag stores the publishers' own profiles.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

from openral_core.errors import OpenralError
from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_best_available,
)
from rclpy.subscription import Subscription
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime as BagTime

from openral_nodes.bag_writer import BagWriter, TopicInfo
from openral_nodes.topic_graph import graph_topics, message_class, topic_name

DISCOVERY_S = 0.5
"""Interval between two looks at the graph for new topics [s]."""
SUBSCRIPTION_DEPTH = 200
"""Messages per topic the middleware keeps for the recorder's callback."""


@dataclass
class BagRecorder:
    """Feeds ``writer`` with the graph's topics (all, or ``topics``) seen by ``node``."""

    node: Node
    writer: BagWriter
    topics: Sequence[str] = ()
    subscriptions: dict[str, Subscription] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.topics = tuple(topic_name(t) for t in self.topics)
        self._timer = self.node.create_timer(DISCOVERY_S, self.discover)

    def discover(self) -> None:
        """Subscribe to each wanted topic that has a publisher and is not recorded yet."""
        wanted = set(self.topics)
        for info in graph_topics(self.node):
            name = info.name
            if name in self.subscriptions or name in self.writer.skipped:
                continue
            if (wanted and name not in wanted) or info.publishers == 0:
                continue
            if len(info.types) != 1:
                self.writer.skipped[name] = f"advertised with {len(info.types)} types"
                continue
            self._subscribe(name, info.types[0])

    def _subscribe(self, name: str, msgtype: str) -> None:
        try:
            cls = message_class(msgtype, name)
        except OpenralError as error:
            self.writer.skipped[name] = str(error)
            return
        publishers = self.node.get_publishers_info_by_topic(name)
        offered = tuple(bag_qos(p.qos_profile) for p in publishers)
        if not self.writer.add_topic(TopicInfo(name, msgtype, offered)):
            return
        qos = QoSProfile(  # type: ignore[no-untyped-call]
            history=HistoryPolicy.KEEP_LAST,
            depth=SUBSCRIPTION_DEPTH,
            reliability=qos_profile_best_available.reliability,
            durability=qos_profile_best_available.durability,
        )
        writer = self.writer

        def take(data: bytes, name: str = name) -> None:
            writer.offer(name, time.time_ns(), data)

        self.subscriptions[name] = self.node.create_subscription(cls, name, take, qos, raw=True)

    def missing(self) -> list[str]:
        """The named topics that never appeared with a publisher."""
        seen = self.subscriptions.keys() | self.writer.skipped.keys()
        return [t for t in self.topics if t not in seen]


_RELIABILITY = {
    ReliabilityPolicy.RELIABLE: QosReliability.RELIABLE,
    ReliabilityPolicy.BEST_EFFORT: QosReliability.BEST_EFFORT,
}
_DURABILITY = {
    DurabilityPolicy.TRANSIENT_LOCAL: QosDurability.TRANSIENT_LOCAL,
    DurabilityPolicy.VOLATILE: QosDurability.VOLATILE,
}
_HISTORY = {
    HistoryPolicy.KEEP_LAST: QosHistory.KEEP_LAST,
    HistoryPolicy.KEEP_ALL: QosHistory.KEEP_ALL,
}
_LIVELINESS = {
    LivelinessPolicy.AUTOMATIC: QosLiveliness.AUTOMATIC,
    LivelinessPolicy.MANUAL_BY_TOPIC: QosLiveliness.MANUAL_BY_TOPIC,
}


def bag_qos(profile: QoSProfile) -> Qos:
    """A publisher's QoS profile as rosbag2 stores it (an unknown policy: system default)."""

    def span(duration: object) -> BagTime:
        nanoseconds = int(getattr(duration, "nanoseconds", 0))
        return BagTime(nanoseconds // 1_000_000_000, nanoseconds % 1_000_000_000)

    return Qos(
        history=_HISTORY.get(profile.history, QosHistory.SYSTEM_DEFAULT),
        depth=int(profile.depth),
        reliability=_RELIABILITY.get(profile.reliability, QosReliability.SYSTEM_DEFAULT),
        durability=_DURABILITY.get(profile.durability, QosDurability.SYSTEM_DEFAULT),
        deadline=span(profile.deadline),
        lifespan=span(profile.lifespan),
        liveliness=_LIVELINESS.get(profile.liveliness, QosLiveliness.SYSTEM_DEFAULT),
        liveliness_lease_duration=span(profile.liveliness_lease_duration),
        avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions),
    )
