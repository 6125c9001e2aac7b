"""Tests for lifecycle_guard.py and manifest_node.py: hostile ChangeState requests, bounds.

Every (state x transition id) pair and a set of labels go to a live ``ManifestLifecycleNode``
through its real ``change_state`` service from an outside client: each gets an answer,
``success`` is true exactly for the transitions the state allows, and the node keeps
spinning. The robot is the bare Panda (no scene), which configures in well under a second.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator

import pytest
from openral_nodes.manifest_node import ManifestLifecycleNode
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.lifecycle import TransitionCallbackReturn

from tests.ros.lifecycle_client import (
    BACK,
    LABELS,
    PATH,
    VALID,
    LifecycleClient,
    outside_client,
)
from tests.ros.ros_helpers import DOMAIN_ID

IDS = (*range(100), 255)
"""Transition ids swept in every state (ChangeState's id is a uint8)."""
ALL_LABELS = ("configure", "cleanup", "activate", "deactivate", "shutdown")
ODD_LABELS = ("bogus", "ACTIVATE", " activate", "unconfigured", "x" * 1000, "aktivieren ✓")
REFUSED = "change_state refused"


@pytest.fixture
def spinner(ros_context: Context) -> Iterator[Spinner]:
    with Spinner(ros_context) as spinner:
        yield spinner


def start_node(
    context: Context, spinner: Spinner, name: str, **parameters: object
) -> tuple[ManifestLifecycleNode, threading.Event]:
    stopped = threading.Event()
    overrides = {"robot_id": "franka_panda", "viewer_enabled": False, **parameters}
    node = ManifestLifecycleNode(
        node_name=name, context=context, parameter_overrides=overrides, shutdown_event=stopped
    )
    spinner.add_node(node)
    return node, stopped


def check(client: LifecycleClient, spinner: Spinner, state: str, ok: bool, expected: bool) -> None:
    assert ok is expected
    assert spinner.running, "the node's executor stopped"
    assert client.state() == state


def sweep(client: LifecycleClient, spinner: Spinner, state: str) -> None:
    """Every id and label in ``state``; a valid non-final transition is undone at once."""
    valid = VALID[state]
    for transition_id in IDS:
        if valid.get(transition_id) == "finalized":
            continue  # shutdown is the test's last transition
        after = valid.get(transition_id, state)
        check(client, spinner, after, client.change(transition_id), transition_id in valid)
        if after != state:
            client.walk(BACK[transition_id])
    for label in (*ALL_LABELS, *ODD_LABELS):
        if label == "shutdown" and state != "finalized":
            continue
        target = LABELS[state].get(label)
        after = state if target is None else valid[target]
        # The label wins over the id: id 3 (activate) is ignored whenever a label is set.
        check(client, spinner, after, client.change(3, label=label), target is not None)
        if target is not None:
            client.walk(BACK[target])


@pytest.mark.parametrize("state", ["unconfigured", "inactive", "active"])
def test_every_transition_request_is_answered_and_never_stops_the_node(
    ros_context: Context, spinner: Spinner, state: str, capfd: pytest.CaptureFixture[str]
) -> None:
    name = f"hostile_{state}"
    node, stopped = start_node(ros_context, spinner, name)
    try:
        with outside_client(DOMAIN_ID, name, f"client_{state}") as client:
            client.wait_ready()
            client.walk(*PATH[state])
            assert client.state() == state
            sweep(client, spinner, state)
            assert not stopped.is_set()
            shutdown = next(t for t, s in VALID[state].items() if s == "finalized")
            check(client, spinner, "finalized", client.change(shutdown), expected=True)
            assert stopped.is_set(), "shutdown must set the owner's shutdown_event"
            assert node.hal is None and node.bridge is None
            sweep(client, spinner, "finalized")
    finally:
        spinner.remove_node(node)
        node.destroy_node()
    log = capfd.readouterr().err
    first = next(line for line in log.splitlines() if REFUSED in line)
    assert f"transition id 0 is not valid in state {state}; valid: " in first
    allowed = ", ".join(f"{label} (id {tid})" for label, tid in LABELS[state].items())
    assert first.endswith(allowed), first
    refusals = log.count(REFUSED)
    assert 1 <= refusals < 20, f"{refusals} refusal warnings: the warning is not throttled"


@pytest.mark.parametrize("state", ["unconfigured", "inactive", "active"])
def test_a_shutdown_by_label_ends_finalized_from_every_state(
    ros_context: Context, spinner: Spinner, state: str
) -> None:
    name = f"shutdown_{state}"
    node, stopped = start_node(ros_context, spinner, name)
    try:
        with outside_client(DOMAIN_ID, name, f"shutdown_client_{state}") as client:
            client.wait_ready()
            client.walk(*PATH[state])
            check(client, spinner, "finalized", client.change(0, label="shutdown"), expected=True)
            assert stopped.is_set()
            check(client, spinner, "finalized", client.change(0, label="shutdown"), expected=False)
    finally:
        spinner.remove_node(node)
        node.destroy_node()


@pytest.mark.parametrize(
    ("parameter", "value", "bounds"),
    [
        ("camera_publish_rate_hz", 0.05, "0.1-1000 Hz (or 0 for each sensor's own rate)"),
        ("camera_publish_rate_hz", -1.0, "0.1-1000 Hz (or 0 for each sensor's own rate)"),
        ("camera_publish_rate_hz", math.inf, "0.1-1000 Hz (or 0 for each sensor's own rate)"),
        ("joint_state_rate_hz", 0.0, "0.1-1000 Hz"),
        ("joint_state_rate_hz", 1e9, "0.1-1000 Hz"),
        ("joint_state_rate_hz", math.nan, "0.1-1000 Hz"),
        ("loop_priority", 100, "0-99 (real-time priority; 0: ordinary scheduling)"),
        ("loop_priority", -1, "0-99 (real-time priority; 0: ordinary scheduling)"),
    ],
)
def test_a_rate_out_of_bounds_is_refused_at_configure_with_the_range(
    ros_context: Context, parameter: str, value: float, bounds: str
) -> None:
    node = ManifestLifecycleNode(
        context=ros_context,
        parameter_overrides={"robot_id": "franka_panda", parameter: value},
        log_boot_errors=False,
    )
    try:
        assert node.trigger_configure() == TransitionCallbackReturn.FAILURE
        assert node.lifecycle_state == "unconfigured" and node.hal is None
        assert node.boot_error is not None
        assert f"parameter {parameter} must be within {bounds}" in node.boot_error
    finally:
        node.destroy_node()


@pytest.mark.parametrize(
    ("parameter", "value"),
    [
        ("camera_publish_rate_hz", 0.1),
        ("camera_publish_rate_hz", 0.0),  # each sensor's own rate
        ("joint_state_rate_hz", 1000.0),
    ],
)
def test_a_rate_on_its_bound_is_accepted(
    ros_context: Context, parameter: str, value: float
) -> None:
    node = ManifestLifecycleNode(
        context=ros_context, parameter_overrides={"robot_id": "franka_panda", parameter: value}
    )
    try:
        assert node.trigger_configure() == TransitionCallbackReturn.SUCCESS, node.boot_error
        assert node.trigger_cleanup() == TransitionCallbackReturn.SUCCESS
    finally:
        node.destroy_node()
