"""Tests for manifest_node.py transitions: boot failures and resource hygiene over cycles."""

from __future__ import annotations

import gc
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from openral_nodes.manifest_node import ManifestLifecycleNode
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.lifecycle import TransitionCallbackReturn

from tests.ros.ros_helpers import FRANKA_SCENE, wait_until

SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE
CYCLES = 20


@pytest.fixture
def spinner(ros_context: Context) -> Iterator[Spinner]:
    with Spinner(ros_context) as spinner:
        yield spinner


def make_node(context: Context, **parameters: object) -> ManifestLifecycleNode:
    defaults = {"sim_env_yaml": str(FRANKA_SCENE), "viewer_enabled": False}
    return ManifestLifecycleNode(context=context, parameter_overrides={**defaults, **parameters})


def test_real_mode_with_a_scene_fails_at_configure_with_the_reason(ros_context: Context) -> None:
    node = make_node(ros_context, hal_mode="real")
    try:
        assert node.trigger_configure() == FAILURE
        assert node.lifecycle_state == "unconfigured"
        assert node.boot_error is not None
        assert "cannot attach to a simulated scene" in node.boot_error
        assert node.hal is None
    finally:
        node.destroy_node()


def test_configure_without_a_robot_names_the_parameters_to_set(ros_context: Context) -> None:
    node = make_node(ros_context, sim_env_yaml="")
    try:
        assert node.trigger_configure() == FAILURE
        assert node.boot_error is not None
        assert "robot_id" in node.boot_error and "manifest_path" in node.boot_error
    finally:
        node.destroy_node()


def test_unknown_parameter_override_is_rejected(ros_context: Context) -> None:
    with pytest.raises(ValueError, match="camera_rate"):
        ManifestLifecycleNode(context=ros_context, parameter_overrides={"camera_rate": 5.0})


def open_fds() -> int:
    gc.collect()  # count what is still referenced, not garbage of earlier tests
    return sum(1 for _ in Path("/proc/self/fd").iterdir())


def native_threads() -> int:
    return sum(1 for _ in Path("/proc/self/task").iterdir())


def cycle(spinner: Spinner, node: ManifestLifecycleNode) -> None:
    """configure → activate → (timers fire) → deactivate → cleanup; the HAL ends closed."""
    assert spinner.call(node.trigger_configure) == SUCCESS
    hal = node.hal
    assert spinner.call(node.trigger_activate) == SUCCESS
    assert hal.connected
    # Let the control loop's timer tick at least once more before tearing it down.
    wait_until(
        lambda: spinner.call(lambda: node.loop is not None and node.loop.ticks >= 2),
        what="a timer tick of the control loop",
    )
    assert spinner.call(node.trigger_deactivate) == SUCCESS
    assert hal.connected, "deactivate must keep the HAL (and its scene) connected"
    assert spinner.call(node.trigger_cleanup) == SUCCESS
    assert not hal.connected, "cleanup must disconnect the HAL (closing its renderers)"


def test_twenty_lifecycle_cycles_leak_no_threads_fds_or_ros_entities(
    ros_context: Context, spinner: Spinner
) -> None:
    node = make_node(ros_context)
    spinner.add_node(node)
    try:
        cycle(spinner, node)  # warm-up: EGL display, DDS participant and caches open once

        def count_entities() -> tuple[int, int]:
            return len(list(node.timers)), len(list(node.publishers))

        entities = spinner.call(count_entities)
        fds, tasks = open_fds(), native_threads()
        threads = sorted(t.name for t in threading.enumerate())
        for _ in range(CYCLES):
            cycle(spinner, node)
        assert spinner.call(count_entities) == entities
        assert entities[0] == 0, "a timer survived cleanup"
        assert open_fds() == fds, f"file descriptors: {fds} before, {open_fds()} after {CYCLES}"
        assert native_threads() == tasks, f"threads: {tasks} before, {native_threads()} after"
        assert sorted(t.name for t in threading.enumerate()) == threads
        assert node.hal is None and node.bridge is None
    finally:
        spinner.remove_node(node)
        node.destroy_node()


@pytest.mark.parametrize(
    ("publish_tf", "publish_static_tf"), [(True, True), (False, True), (False, False)]
)
def test_publish_tf_false_leaves_tf_to_another_node_and_keeps_the_description(
    ros_context: Context, spinner: Spinner, publish_tf: bool, publish_static_tf: bool
) -> None:
    """--no-tf leaves the URDF's transforms to a robot_state_publisher and keeps sending what
    no URDF holds (world → base_link, the scene's cameras); --no-static-tf leaves out those
    too (the fixed Panda then sends no transform at all)."""
    node = make_node(ros_context, publish_tf=publish_tf, publish_static_tf=publish_static_tf)
    spinner.add_node(node)
    try:
        assert spinner.call(node.trigger_configure) == SUCCESS
        assert spinner.call(node.trigger_activate) == SUCCESS

        def topics() -> set[str]:
            return {p.topic_name for p in node.publishers}

        published = spinner.call(topics)
        assert ({"/tf", "/tf_static"} <= published) is publish_static_tf
        assert not ({"/tf", "/tf_static"} & published) or publish_static_tf
        tf = node.states.tf if node.states is not None else None
        if tf is not None:
            sent = {tf.tree.frames[int(r)].name for r in [*tf.static, *tf.dynamic]}
            urdf = {link.name for link in tf.tree.tree.links} - {tf.tree.tree.base}
            assert bool(sent & urdf) is publish_tf, sent & urdf
            assert ("agentview_optical_frame" in sent) is publish_static_tf
        assert {"/joint_states", "/robot_description"} <= published
        assert spinner.call(node.trigger_deactivate) == SUCCESS
        assert spinner.call(node.trigger_cleanup) == SUCCESS
    finally:
        spinner.remove_node(node)
        node.destroy_node()
