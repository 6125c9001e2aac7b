"""Outside peers for the hostile-peer tests: a lifecycle client and a deploy-sim process.

The client lives on a context of its own (its own DDS participant), as another process
would, and calls the node's services the way ``ros2 lifecycle set`` does. Every call waits
for its response with a generous timeout and fails the test when none comes.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
from openral_nodes.runtime import Spinner, ros_session
from rclpy.node import Node
from std_srvs.srv import Trigger

from tests.ros.ros_helpers import WAIT_S

T = Transition
VALID: dict[str, dict[int, str]] = {
    "unconfigured": {
        T.TRANSITION_CONFIGURE: "inactive",
        T.TRANSITION_UNCONFIGURED_SHUTDOWN: "finalized",
    },
    "inactive": {
        T.TRANSITION_CLEANUP: "unconfigured",
        T.TRANSITION_ACTIVATE: "active",
        T.TRANSITION_INACTIVE_SHUTDOWN: "finalized",
    },
    "active": {T.TRANSITION_DEACTIVATE: "inactive", T.TRANSITION_ACTIVE_SHUTDOWN: "finalized"},
    "finalized": {},
}
"""Transition ids each primary state allows, and the state each one leads to."""

LABELS: dict[str, dict[str, int]] = {
    "unconfigured": {
        "configure": T.TRANSITION_CONFIGURE,
        "shutdown": T.TRANSITION_UNCONFIGURED_SHUTDOWN,
    },
    "inactive": {
        "cleanup": T.TRANSITION_CLEANUP,
        "activate": T.TRANSITION_ACTIVATE,
        "shutdown": T.TRANSITION_INACTIVE_SHUTDOWN,
    },
    "active": {"deactivate": T.TRANSITION_DEACTIVATE, "shutdown": T.TRANSITION_ACTIVE_SHUTDOWN},
    "finalized": {},
}
"""Transition labels each primary state allows, with the id each one stands for."""

BACK: dict[int, int] = {
    T.TRANSITION_CONFIGURE: T.TRANSITION_CLEANUP,
    T.TRANSITION_CLEANUP: T.TRANSITION_CONFIGURE,
    T.TRANSITION_ACTIVATE: T.TRANSITION_DEACTIVATE,
    T.TRANSITION_DEACTIVATE: T.TRANSITION_ACTIVATE,
}
"""The transition that undoes each reversible one."""

PATH: dict[str, tuple[int, ...]] = {
    "unconfigured": (),
    "inactive": (T.TRANSITION_CONFIGURE,),
    "active": (T.TRANSITION_CONFIGURE, T.TRANSITION_ACTIVATE),
}
"""Transitions from unconfigured to each primary state a node can be brought to."""

TRANSITION_WAIT_S = 60.0
"""Longest wait for a transition that builds a HAL and its scene on a loaded machine [s]."""


OPENRAL = Path(sys.executable).parent / "openral"
DEPLOY_ENV = {**os.environ, "MUJOCO_GL": "egl", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
DEPLOY_NODE = "openral_manifest_node"
"""Name of the node ``openral deploy sim`` runs."""
DRIVER_PRIORITY = 50
"""Real-time priority of a stand-in driver's loop: ros2_control_node's default
``thread_priority``, above ``deploy real``'s reader (:data:`openral_hal.realtime.PRIORITY`)."""
STOP_WAIT_S = 30.0
"""Longest wait for a deploy process to end after SIGTERM before it is killed [s]."""


class LifecycleClient:
    """ChangeState / GetState (and any Trigger service) calls from a node of its own."""

    def __init__(self, node: Node, target: str, spinner: Spinner) -> None:
        self.node = node
        self.spinner = spinner
        """The spinner of the client's context (add probe nodes to it)."""
        self.target = target
        self._change = node.create_client(ChangeState, f"/{target}/change_state")
        self._get = node.create_client(GetState, f"/{target}/get_state")
        self._triggers: dict[str, Any] = {}

    def wait_ready(self, timeout_s: float = WAIT_S) -> None:
        """Wait until both lifecycle services of the target are discovered."""
        for client in (self._change, self._get):
            if not client.wait_for_service(timeout_sec=timeout_s):
                pytest.fail(f"{client.srv_name} not discovered within {timeout_s} s")

    def change(self, transition_id: int = 0, label: str = "", timeout_s: float = WAIT_S) -> bool:
        """Request a transition by id (and label, which wins when set); its ``success``."""
        request = ChangeState.Request()
        request.transition.id, request.transition.label = transition_id, label
        response = self._call(self._change, request, timeout_s, f"change_state {request}")
        return bool(response.success)

    def state(self, timeout_s: float = WAIT_S) -> str:
        """The target's current state label, asked over its get_state service."""
        response = self._call(self._get, GetState.Request(), timeout_s, "get_state")
        label: str = response.current_state.label
        return label

    def trigger(self, service: str, timeout_s: float = WAIT_S) -> tuple[Any, float]:
        """Call a ``std_srvs/Trigger`` service; the response and its round trip [s]."""
        client = self._triggers.get(service)
        if client is None:
            client = self._triggers[service] = self.node.create_client(Trigger, service)
            if not client.wait_for_service(timeout_sec=timeout_s):
                pytest.fail(f"{service} not discovered within {timeout_s} s")
        started = time.monotonic()
        response = self._call(client, Trigger.Request(), timeout_s, service)
        return response, time.monotonic() - started

    def walk(self, *transition_ids: int) -> None:
        """Run valid transitions in order; each must succeed."""
        for transition_id in transition_ids:
            ok = self.change(transition_id, timeout_s=TRANSITION_WAIT_S)
            assert ok, f"transition {transition_id} failed"

    @staticmethod
    def _call(client: Any, request: Any, timeout_s: float, what: str) -> Any:
        response = client.call(request, timeout_sec=timeout_s)
        if response is None:
            pytest.fail(f"no response to {what} within {timeout_s} s")
        return response


@contextmanager
def outside_client(domain_id: int, target: str, name: str) -> Iterator[LifecycleClient]:
    """A :class:`LifecycleClient` on its own context and spinner in ``domain_id``."""
    with ros_session(domain_id=domain_id) as context, Spinner(context) as spinner:
        client = LifecycleClient(Node(name, context=context), target, spinner)
        spinner.add_node(client.node)
        try:
            yield client
        finally:
            spinner.stop()
            client.node.destroy_node()


@contextmanager
def deploy_sim(
    config: Path, domain_id: int, logs: Path, extra: Sequence[str] = (), *, robot: bool = False
) -> Iterator[subprocess.Popen[str]]:
    """``openral deploy sim --config CONFIG --no-viewer [EXTRA…]`` in ``domain_id`` as a
    subprocess; ``robot``: standing in for a robot's driver, ahead of ordinary programs
    (``nice -n -20``) and its control loop at real-time priority :data:`DRIVER_PRIORITY`,
    as a ros2_control driver's loop runs (its 100 Hz stream then keeps time while other
    programs start beside it, and ahead of ``deploy real``'s reader).

    Its stdout and stderr go to ``logs/deploy.out`` and ``logs/deploy.err`` (files, not
    pipes, so a chatty process never blocks on a full pipe). Still alive on exit, it gets
    SIGTERM, then SIGKILL after :data:`STOP_WAIT_S`.
    """
    command = ["nice", "-n", "-20"] if robot else []
    command += [str(OPENRAL), "deploy", "sim", "--config", str(config), "--no-viewer"]
    command += ["--domain-id", str(domain_id), *extra]
    if robot:  # a driver renders no cameras (a frame drawn on the CPU holds Python's lock)
        command += ["--camera-rate", "0.1", "--loop-priority", str(DRIVER_PRIORITY)]
    with (logs / "deploy.out").open("w") as out, (logs / "deploy.err").open("w") as err:
        process = subprocess.Popen(command, stdout=out, stderr=err, text=True, env=DEPLOY_ENV)
        try:
            yield process
        finally:
            if process.poll() is None:
                process.terminate()
            try:
                process.wait(STOP_WAIT_S)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def deploy_output(logs: Path) -> tuple[str, str]:
    """What a :func:`deploy_sim` process wrote so far: (stdout, stderr)."""
    return (logs / "deploy.out").read_text(), (logs / "deploy.err").read_text()
