"""``openral ros topics`` lists the graph once discovery has settled: a topic whose
endpoint is discovered late (a subscriber-only /cmd_vel) is still listed."""

from __future__ import annotations

import time

from openral_nodes.topic_graph import SETTLED_S, settled_topics


class _Graph:
    """A node whose discovery cache fills in over time: (after s, name, type) entries."""

    def __init__(self, arrivals: list[tuple[float, str, str]]) -> None:
        self.start = time.monotonic()
        self.arrivals = arrivals

    def get_topic_names_and_types(self) -> list[tuple[str, list[str]]]:
        now = time.monotonic() - self.start
        return [(name, [kind]) for after, name, kind in self.arrivals if now >= after]

    def count_publishers(self, name: str) -> int:
        return 0 if name == "/cmd_vel" else 1


def test_a_topic_discovered_after_the_wait_is_listed() -> None:
    graph = _Graph(
        [
            (0.0, "/joint_states", "sensor_msgs/msg/JointState"),
            (0.4, "/cmd_vel", "geometry_msgs/msg/Twist"),
        ]
    )
    infos, waited = settled_topics(graph, wait_s=0.2, longest_s=3.0)  # type: ignore[arg-type]
    assert [i.name for i in infos] == ["/cmd_vel", "/joint_states"]
    assert 0.4 + SETTLED_S <= waited < 3.0


def test_an_empty_graph_gives_up_after_the_longest_wait() -> None:
    infos, waited = settled_topics(_Graph([]), wait_s=0.1, longest_s=0.5)  # type: ignore[arg-type]
    assert infos == [] and 0.5 <= waited < 1.0
