"""UnlockedPublisher: what it sends arrives as sent, a wrong type is refused, and Python's
other threads run while the middleware holds the call (rclpy's own publish stops them)."""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from itertools import pairwise

import pytest
from openral_hal.unlocked_publisher import UnlockedPublisher
from openral_nodes.graph_names import namespaced_node
from rclpy.context import Context
from rclpy.node import Node
from rclpy.serialization import serialize_message
from sensor_msgs.msg import Image, JointState

from tests.ros.ros_helpers import wait_until

pytestmark = pytest.mark.exclusive  # it measures how threads share the interpreter

PAYLOAD_BYTES = 64_000_000
"""A 64 MB image: the middleware takes several milliseconds to take it."""


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    made = Node("unlocked_publisher_test", context=ros_context)
    yield made
    made.destroy_node()


def test_messages_arrive_as_sent_and_a_wrong_type_is_refused(node: Node) -> None:
    publisher = node.create_publisher(
        JointState, "/unlocked/joint_states", 10, publisher_class=UnlockedPublisher
    )
    received: list[JointState] = []
    node.create_subscription(JointState, "/unlocked/joint_states", received.append, 10)
    sent = JointState(name=["a", "b"], position=[0.25, -1.5], velocity=[0.0, 2.0])
    executor_spin = _spinner(node)
    try:
        wait_until(lambda: publisher.get_subscription_count() > 0, 10.0)
        publisher.publish(sent)
        publisher.publish(serialize_message(sent))  # already serialised: sent as it is
        wait_until(lambda: len(received) >= 2, 10.0)
    finally:
        executor_spin()
    assert all(message == sent for message in received[:2])
    with pytest.raises(TypeError, match="JointState"):
        publisher.publish("not a joint state")


def test_a_graph_node_publishes_unlocked(ros_context: Context) -> None:
    graph_node = namespaced_node("unlocked_graph_node", "/arm", context=ros_context)
    try:
        publisher = graph_node.create_publisher(JointState, "/joint_states", 10)
        assert isinstance(publisher, UnlockedPublisher)
        assert publisher.topic_name == "/arm/joint_states"
    finally:
        graph_node.destroy_node()


def test_other_threads_run_while_it_sends(node: Node) -> None:
    unlocked = node.create_publisher(Image, "/unlocked/big", 1, publisher_class=UnlockedPublisher)
    locked = node.create_publisher(Image, "/locked/big", 1)
    payload = serialize_message(Image(data=bytes(PAYLOAD_BYTES)))
    held = _held_share(lambda: unlocked.publish(payload))
    control = _held_share(lambda: locked.handle.publish_raw(payload))
    assert control > 0.8, f"the control (rclpy's publish) left the others {1 - control:.0%}"
    assert held < 0.5, f"the other thread stood still for {held:.0%} of the publish"


def _held_share(publish: Callable[[], None], tries: int = 3) -> float:
    """The least, over ``tries``, of the longest pause of a busy second thread during
    ``publish``, as a share of the call's time (1: it never ran)."""
    best, switch = 1.0, sys.getswitchinterval()
    sys.setswitchinterval(1e-4)  # the threads hand Python's lock over at once when it is free
    try:
        for _ in range(tries):
            best = min(best, _held_once(publish))
    finally:
        sys.setswitchinterval(switch)
    return best


def _held_once(publish: Callable[[], None]) -> float:
    """The longest pause of a busy second thread during ``publish`` over the call's time."""
    beats: list[float] = []
    stop = threading.Event()

    def busy() -> None:
        while not stop.is_set():
            beats.append(time.perf_counter())

    thread = threading.Thread(target=busy, daemon=True)
    thread.start()
    time.sleep(0.05)
    began = time.perf_counter()
    publish()
    ended = time.perf_counter()
    stop.set()
    thread.join()
    inside = [began] + [beat for beat in beats if began < beat < ended] + [ended]
    longest = max(b - a for a, b in pairwise(inside))
    return longest / (ended - began)


def _spinner(node: Node) -> Callable[[], None]:
    """Spin ``node`` on a thread; the returned call stops it."""
    from rclpy.executors import SingleThreadedExecutor

    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    thread = threading.Thread(target=executor.spin, daemon=True)
    thread.start()

    def stop() -> None:
        executor.shutdown(timeout_sec=2.0)
        thread.join(5.0)

    return stop
