"""Fixtures of the deploy-sim tests: an rclpy context on this process's own domain and the
franka default scene running as a live node (see ``ros_helpers`` for the isolation rules)."""

from __future__ import annotations

import gc
import time
from collections.abc import Iterator

import pytest
from openral_bridge.pacer import Pacer
from openral_core.registry import load_robot_by_id
from openral_nodes.manifest_node import ManifestLifecycleNode
from openral_nodes.runtime import Spinner, ros_session
from rclpy.context import Context
from rclpy.lifecycle import TransitionCallbackReturn

from tests.ros.ros_helpers import DOMAIN_ID, FRANKA_SCENE, PROBE_TOPICS, Deployed, Probe


@pytest.fixture(scope="module")
def ros_context() -> Iterator[Context]:
    """An rclpy context on this process's domain."""
    with ros_session(domain_id=DOMAIN_ID) as context:
        yield context


@pytest.fixture(scope="module")
def deployed(ros_context: Context) -> Iterator[Deployed]:
    """``deploy sim`` on the franka default scene, in-process, headless, probed from the start.

    The graph shares this process with every object the suite made before it, which a
    ``deploy sim`` process would not: they are frozen out of garbage collection while it
    runs (``gc.freeze``), so a collection of the suite's garbage never stalls its threads.
    """
    gc.collect()
    gc.freeze()
    spinner = Spinner(ros_context).start()
    probe = Probe(ros_context, PROBE_TOPICS)
    spinner.add_node(probe.node)
    node = ManifestLifecycleNode(
        context=ros_context,
        parameter_overrides={
            "sim_env_yaml": str(FRANKA_SCENE),
            "viewer_enabled": False,
        },
    )
    spinner.add_node(node)
    assert spinner.call(node.trigger_configure) == TransitionCallbackReturn.SUCCESS
    assert spinner.call(node.trigger_activate) == TransitionCallbackReturn.SUCCESS
    activated_at = time.monotonic()
    try:
        yield Deployed(node, probe, spinner, load_robot_by_id("franka_panda"), activated_at)
    finally:
        spinner.call(node.trigger_deactivate)
        spinner.call(node.trigger_cleanup)
        spinner.stop()
        node.destroy_node()
        probe.node.destroy_node()
        gc.unfreeze()


@pytest.fixture
def pacer() -> Iterator[Pacer]:
    """A running pacer, stopped (and joined) after the test."""
    pacer = Pacer()
    pacer.start()
    yield pacer
    assert pacer.stop()
