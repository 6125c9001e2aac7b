"""JointStatePublisher: /joint_states and /openral/manifest_joint_states from a pacer job,
read holding the HAL's lock, one message built per control tick's reading."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from openral_bridge.joint_state_publisher import (
    HalStates,
    JointStatePublisher,
    StateReading,
)
from openral_bridge.pacer import Pacer
from openral_mujoco.state import JointStateSample
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import JointState

from tests.ros.ros_helpers import Probe

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone


class StateHal:
    """Counts reads and whether each held the lock."""

    def __init__(self, lock: threading.Lock, sim_time_s: float | None = 3.25) -> None:
        self.lock = lock
        self.sim_time_s = sim_time_s
        self.reads = 0
        self.unlocked_reads = 0

    def read_state(self) -> JointStateSample:
        self.reads += 1
        self.unlocked_reads += int(not self.lock.locked())
        values = np.array([0.5, -1.0])
        return JointStateSample(("a", "b"), values, values * 2, values * 3, 0, self.sim_time_s)


@pytest.fixture
def node(ros_context: Context) -> Iterator[Node]:
    node = Node("joint_state_publisher_test", context=ros_context)
    yield node
    node.destroy_node()


def received(
    ros_context: Context, node: Node, publisher: JointStatePublisher, count: int
) -> list[Any]:
    """Start ``publisher`` on a pacer, return the first ``count`` messages, stop both; the
    job and the publisher are gone then."""
    topics = {"/joint_states": JointState, "/openral/manifest_joint_states": JointState}
    probe = Probe(ros_context, topics, name="joint_state_probe")
    publishers = len(list(node.publishers))
    pacer = Pacer()
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        publisher.start(pacer)
        pacer.start()
        messages = probe.wait_count("/joint_states", count)
        assert pacer.stop()
        publisher.stop()
    probe.node.destroy_node()
    assert pacer.jobs == () and len(list(node.publishers)) == publishers
    return [r.msg for r in messages]


def test_reads_the_hal_holding_its_lock_and_stamps_simulated_time(
    ros_context: Context, node: Node
) -> None:
    lock = threading.Lock()
    hal = StateHal(lock)
    source = HalStates(hal, lock)  # type: ignore[arg-type]
    publisher = JointStatePublisher(node, 50.0, source)
    messages = received(ros_context, node, publisher, 3)
    assert hal.reads >= 3 and hal.unlocked_reads == 0
    first = messages[0]
    assert list(first.name) == ["a", "b"]
    assert list(first.position) == [0.5, -1.0] and list(first.effort) == [1.5, -3.0]
    assert (first.header.stamp.sec, first.header.stamp.nanosec) == (3, 250_000_000)


class FixedSource:
    """One reading, for ever (as a control loop's between two ticks)."""

    def __init__(self, reading: StateReading) -> None:
        self.value = reading
        self.calls = 0

    def reading(self) -> StateReading:
        self.calls += 1
        return self.value


def test_a_tick_reading_is_built_once_and_sent_until_the_next(
    ros_context: Context, node: Node
) -> None:
    joints = StateHal(threading.Lock(), sim_time_s=7.0).read_state()
    manifest = joints._replace(positions=joints.positions / 10)
    source = FixedSource(StateReading(joints, manifest))
    publisher = JointStatePublisher(node, 50.0, source)
    built: list[object] = []
    original = publisher._messages_of

    def counted(reading: StateReading) -> tuple[object, object]:
        messages = original(reading)
        if not built or built[-1] is not messages[0]:
            built.append(messages[0])
        return messages

    publisher._messages_of = counted  # type: ignore[method-assign]
    messages = received(ros_context, node, publisher, 4)
    assert source.calls >= 4 and len(built) == 1  # one pair of messages built
    assert all(m.header.stamp.sec == 7 for m in messages)
    assert all(list(m.position) == [0.5, -1.0] for m in messages)


def test_the_manifest_view_goes_to_its_own_topic(ros_context: Context, node: Node) -> None:
    joints = StateHal(threading.Lock(), sim_time_s=2.0).read_state()
    manifest = joints._replace(names=("m",), positions=np.array([0.25]))
    manifest = manifest._replace(velocities=np.zeros(1), efforts=np.zeros(1))
    publisher = JointStatePublisher(node, 50.0, FixedSource(StateReading(joints, manifest)))
    probe = Probe(ros_context, {"/openral/manifest_joint_states": JointState}, name="m_probe")
    pacer = Pacer()
    with Spinner(ros_context) as spinner:
        spinner.add_node(probe.node)
        spinner.add_node(node)
        publisher.start(pacer)
        pacer.start()
        message = probe.wait_count("/openral/manifest_joint_states", 1)[0].msg
        assert pacer.stop()
        publisher.stop()
    probe.node.destroy_node()
    assert list(message.name) == ["m"] and list(message.position) == [0.25]


def test_without_simulated_time_it_reads_and_uses_the_node_clock(
    ros_context: Context, node: Node
) -> None:
    lock = threading.Lock()
    hal = StateHal(lock, sim_time_s=None)
    publisher = JointStatePublisher(node, 50.0, HalStates(hal, lock))  # type: ignore[arg-type]
    before = time.time()
    messages = received(ros_context, node, publisher, 2)
    assert hal.reads >= 2
    stamp_s = messages[0].header.stamp.sec + messages[0].header.stamp.nanosec * 1e-9
    assert stamp_s >= before - 1.0  # wall-clock time of the node's clock
