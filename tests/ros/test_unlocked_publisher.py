"""UnlockedPublisher: what it sends arrives as sent, a wrong type is refused, and Python's
other threads run while the middleware holds the call (rclpy's own publish stops them)."""

from __future__ import annotations

import ctypes
import sys
import threading
import time
from collections.abc import Callable, Iterator
from itertools import pairwise
from typing import Any

import pytest
from openral_hal.unlocked_publisher import UnlockedPublisher, _rcl, rcl_error
from openral_nodes.graph_names import namespaced_node
from rclpy.context import Context
from rclpy.node import Node
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
        publisher.publish(sent)
        wait_until(lambda: len(received) >= 2, 10.0)
    finally:
        executor_spin()
    assert all(message == sent for message in received[:2])
    with pytest.raises(TypeError, match="JointState"):
        publisher.publish("not a joint state")


def test_the_bytes_on_the_wire_are_rclpys_own(node: Node) -> None:
    """Byte for byte what rclpy's publish sends (an empty array too: a bag reader checks the
    size), so recorders and bag readers see no difference."""
    unlocked = node.create_publisher(
        JointState, "/wire/unlocked", 10, publisher_class=UnlockedPublisher
    )
    locked = node.create_publisher(JointState, "/wire/locked", 10)
    raw: dict[str, list[bytes]] = {"/wire/unlocked": [], "/wire/locked": []}
    for topic, got in raw.items():
        node.create_subscription(JointState, topic, got.append, 10, raw=True)
    sent = JointState(name=["a", "panda_joint7"], position=[0.1, 0.2], velocity=[0.3, 0.4])
    stop = _spinner(node)
    try:
        deadline = time.monotonic() + 10.0  # published until both are heard (discovery)
        while min(len(got) for got in raw.values()) < 5:
            assert time.monotonic() < deadline, {topic: len(got) for topic, got in raw.items()}
            unlocked.publish(sent)
            locked.publish(sent)
            time.sleep(0.05)
    finally:
        stop()
    assert len(set(raw["/wire/locked"])) == 1  # one message, one set of bytes
    assert set(raw["/wire/unlocked"]) == set(raw["/wire/locked"])


def test_rcls_refusal_is_read_as_text() -> None:
    """The error path: rcl's own text (the error string is a struct returned by value)."""
    assert _rcl().rcl_publish(None, None, None) != 0
    assert "publisher pointer is invalid" in rcl_error(1)
    assert rcl_error(1) == "rcl 1"  # reset: nothing left to say


def test_a_graph_node_publishes_unlocked(ros_context: Context) -> None:
    graph_node = namespaced_node("unlocked_graph_node", "/arm", context=ros_context)
    try:
        publisher = graph_node.create_publisher(JointState, "/joint_states", 10)
        assert isinstance(publisher, UnlockedPublisher)
        assert publisher.topic_name == "/arm/joint_states"
    finally:
        graph_node.destroy_node()


def test_other_threads_run_while_rcl_sends(node: Node, monkeypatch: pytest.MonkeyPatch) -> None:
    """The longest pause of a busy second thread inside the ``rcl_publish`` call: short with
    the library loaded as it is; the whole call with the same library loaded to keep the
    lock (the control: the measurement can fail)."""
    publisher = node.create_publisher(Image, "/unlocked/big", 1, publisher_class=UnlockedPublisher)
    image = Image(height=1, width=PAYLOAD_BYTES, encoding="mono8", step=PAYLOAD_BYTES)
    image.data = bytes(PAYLOAD_BYTES)
    as_loaded = _rcl()
    keeping = ctypes.PyDLL(as_loaded._name)
    for library in (as_loaded, keeping):
        library.rcl_publish.argtypes = [ctypes.c_void_p] * 3
        library.rcl_publish.restype = ctypes.c_int
    held = _held_share(publisher, image, as_loaded, monkeypatch)
    control = _held_share(publisher, image, keeping, monkeypatch)
    assert control > 0.8, f"the control (the lock kept) left the other thread {1 - control:.0%}"
    assert held < 0.5, f"the other thread stood still for {held:.0%} of rcl_publish"


class _Timed:
    """rcl's library with ``rcl_publish`` timed [s, perf_counter]."""

    def __init__(self, library: ctypes.CDLL) -> None:
        self.library = library
        self.window = (0.0, 0.0)

    def rcl_publish(self, *args: object) -> int:
        began = time.perf_counter()
        code = int(self.library.rcl_publish(*args))
        self.window = (began, time.perf_counter())
        return code

    def __getattr__(self, name: str) -> object:
        return getattr(self.library, name)


def _held_share(
    publisher: Any, image: Image, library: ctypes.CDLL, monkeypatch: pytest.MonkeyPatch
) -> float:
    """The least, over three tries, of the longest pause of a busy second thread inside
    ``rcl_publish`` (``library``'s), as a share of that call's time (1: it never ran)."""
    timed = _Timed(library)
    monkeypatch.setattr("openral_hal.unlocked_publisher._rcl", lambda: timed)
    best, switch = 1.0, sys.getswitchinterval()
    sys.setswitchinterval(1e-4)  # the threads hand Python's lock over at once when it is free
    try:
        for _ in range(3):
            beats = _beats_during(lambda: publisher.publish(image))
            began, ended = timed.window
            inside = [began] + [beat for beat in beats if began < beat < ended] + [ended]
            best = min(best, max(b - a for a, b in pairwise(inside)) / (ended - began))
    finally:
        sys.setswitchinterval(switch)
    return best


def _beats_during(call: Callable[[], None]) -> list[float]:
    """The times [s, perf_counter] a busy second thread ran at while ``call`` ran."""
    beats: list[float] = []
    stop = threading.Event()

    def busy() -> None:
        while not stop.is_set():
            beats.append(time.perf_counter())

    thread = threading.Thread(target=busy, daemon=True)
    thread.start()
    time.sleep(0.05)
    call()
    stop.set()
    thread.join()
    return beats


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
