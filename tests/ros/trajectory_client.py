"""A client of a live franka tabletop graph for the trajectory and reset tests.

``openral deploy sim`` runs as a subprocess on a ROS domain of its own; the client records
``/joint_states``, ``/clock``, the trajectory state and the wrist camera (subscribed before
the graph starts, so it sees the very first frame), publishes trajectories and actions,
and calls the Trigger services.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from openral_bridge.topics import (
    CLOCK,
    ESTOP,
    JOINT_STATES,
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_REFUSED,
    JOINT_TRAJECTORY_STATE,
    RELEASE_ESTOP,
    RESET,
    SAFE_ACTION,
    camera_image,
)
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory

from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import FRANKA_SCENE, Probe, call_trigger, wait_until

START_WAIT_S = 90.0
"""Longest wait for deploy sim to load its scene and publish on a loaded machine [s]."""
JOINTS = ("panda_joint1", "panda_joint4")
WRIST = camera_image("wrist")


def stamp_s(msg: Any) -> float:
    """A message's header stamp [s]."""
    return float(msg.header.stamp.sec) + float(msg.header.stamp.nanosec) * 1e-9


@dataclass
class Client:
    """A probe of the graph, a trajectory and an action publisher, the services."""

    probe: Probe
    logs: Path
    domain: int
    trajectory: Any
    action: Any
    services: dict[str, Any]

    @property
    def env(self) -> dict[str, str]:
        """An environment for an ``openral`` subprocess on the graph's domain."""
        return {**os.environ, "ROS_DOMAIN_ID": str(self.domain), "COLUMNS": "200"}

    def call(self, name: str) -> Any:
        """Call a Trigger service and return its response."""
        return call_trigger(self.services[name], name)

    def positions(self, msg: Any) -> np.ndarray:
        """Positions of :data:`JOINTS` in a JointState."""
        names = list(msg.name)
        return np.array([msg.position[names.index(j)] for j in JOINTS])

    def now_s(self) -> float:
        """The graph's simulated time: the last ``/clock`` [s]."""
        clock = self.probe.latest(CLOCK).clock
        return float(clock.sec) + clock.nanosec * 1e-9

    def state_at(self, time_s: float, after: float = 0.0) -> Any:
        """The first /joint_states message stamped at or after ``time_s`` (waits for it).

        Under load the publisher may skip a tick, so the caller reads the stamp it got;
        one later than a skipped tick or two fails."""

        def matching() -> list[Any]:
            received = self.probe.since(JOINT_STATES, after)
            return [r.msg for r in received if stamp_s(r.msg) >= time_s - 1e-6]

        self.probe.wait(lambda: bool(matching()), 15.0, f"/joint_states stamped {time_s:.3f} s")
        found = min(matching(), key=stamp_s)
        assert stamp_s(found) - time_s < 0.15, f"first state after {time_s} s: {stamp_s(found)} s"
        return found

    def stderr(self) -> str:
        """What the graph logged so far."""
        return deploy_output(self.logs)[1]


def franka_graph(logs: Path) -> Iterator[Client]:
    """The franka tabletop as a live graph and a client of it (a fixture's body)."""
    domain = claim_domain_id()
    topics = {
        JOINT_STATES: JointState,
        CLOCK: Clock,
        JOINT_TRAJECTORY_STATE: JointState,
        JOINT_TRAJECTORY_REFUSED: String,
    }
    with ros_session(domain_id=domain) as context:
        probe = Probe(context, {**topics, WRIST: Image}, name="trajectory_client")
        with Spinner(context) as spinner, deploy_sim(FRANKA_SCENE, domain, logs) as process:
            spinner.add_node(probe.node)
            for topic in (JOINT_STATES, CLOCK, WRIST):
                probe.wait_count(topic, 1, timeout_s=START_WAIT_S)
            node = probe.node
            services = (RESET, ESTOP, RELEASE_ESTOP)
            client = Client(
                probe,
                logs,
                domain,
                node.create_publisher(JointTrajectory, JOINT_TRAJECTORY, 10),
                node.create_publisher(Float64MultiArray, SAFE_ACTION, 10),
                {name: node.create_client(Trigger, name) for name in services},
            )
            wait_until(lambda: client.trajectory.get_subscription_count() > 0, 10.0, "subscriber")
            assert process.poll() is None, deploy_output(logs)
            yield client
        probe.node.destroy_node()  # type: ignore[no-untyped-call]
