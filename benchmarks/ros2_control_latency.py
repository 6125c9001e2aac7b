"""deploy real on a ros2_control driver: from a policy's action to the driver's command.

deploy sim runs the Panda as "the robot" in namespace /robot (its trajectory controller's
topic is the command a franka_ros2 driver would take) and deploy real drives it through
``--transport ros2_control:robot`` under /real, on a domain of their own. This process
publishes actions on ``/real/openral/safe_action`` (joint 1 a little one way, then the
other, every half second) and listens to ``/robot/joint_trajectory_controller/joint_trajectory``;
one clock stamps both sides (``time.monotonic()`` at publish and at arrival). Measured in the
same run:

- **hop**: one DDS hop on this machine (this process to itself over the same transport),
  the floor of any path through a second process;
- **action → command**: from publishing an action to the first trajectory point that moves
  towards it; it holds two hops, deploy real's wait for the robot's next reading (its cycle:
  up to one 10 ms period) and its work. The line: the added latency (action → command less
  two hops) at most one control period.

Writes ``benchmarks/results/ros2_control_latency.json``. In simulation, not on hardware.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import rclpy
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from rich.console import Console
from rich.table import Table
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory

from benchmarks.results_file import write_results

OPENRAL = Path(sys.executable).parent / "openral"
SCENE = Path(__file__).parents[1] / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
PERIOD_S = 0.01
"""The Panda's real.control_rate_hz is 100."""
ROBOT = ["nice", "-n", "-20", str(OPENRAL), "deploy", "sim", "--config", str(SCENE),
         "--no-viewer", "--namespace", "robot", "--camera-rate", "0.1"]  # fmt: skip
"""The robot: deploy sim ahead of ordinary programs, as a driver's loop runs."""
REAL = [str(OPENRAL), "deploy", "real", "--robot", "franka_panda", "--transport",
        "ros2_control:robot", "--namespace", "real"]  # fmt: skip
STEP_RAD = 0.02
GAP_S = 0.5


class Client:
    """Actions out, the robot's commands and a ping in, each stamped on arrival."""

    def __init__(self, node: Node) -> None:
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.spec: JointState | None = None
        self.commands: list[tuple[float, float]] = []
        self.pings: list[float] = []
        self.lock = threading.Lock()
        node.create_subscription(JointState, "/real/openral/action_spec", self._spec, latched)
        node.create_subscription(
            JointTrajectory, "/robot/joint_trajectory_controller/joint_trajectory", self._cmd, 100
        )
        node.create_subscription(Float64MultiArray, "/bench/ping", self._ping, 100)
        self.actions = node.create_publisher(Float64MultiArray, "/real/openral/safe_action", 10)
        self.ping = node.create_publisher(Float64MultiArray, "/bench/ping", 10)

    def _spec(self, msg: JointState) -> None:
        self.spec = msg

    def _cmd(self, msg: JointTrajectory) -> None:
        at = time.monotonic()
        index = list(msg.joint_names).index("panda_joint1")
        with self.lock:
            self.commands.append((at, float(msg.points[0].positions[index])))

    def _ping(self, msg: Float64MultiArray) -> None:
        with self.lock:
            self.pings.append(time.monotonic() - msg.data[0])


def _wait(predicate: object, timeout_s: float, what: str) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():  # type: ignore[operator]
        if time.monotonic() > deadline:
            raise SystemExit(f"timed out waiting for {what}")
        time.sleep(0.05)


def _trial(client: Client, hold: np.ndarray, sign: float) -> float | None:
    """One action; the seconds until the first command that moves towards it (None: none)."""
    with client.lock:
        before = client.commands[-1][1]
    action = hold.copy()
    action[0] += sign * STEP_RAD
    sent = time.monotonic()
    client.actions.publish(Float64MultiArray(data=action.tolist()))
    time.sleep(GAP_S)
    with client.lock:
        after = [(t, q) for t, q in client.commands if t >= sent]
    moved = [t for t, q in after if (q - before) * sign > 1e-9]
    return moved[0] - sent if moved else None


def _hops(client: Client, count: int) -> list[float]:
    for _ in range(count):
        client.ping.publish(Float64MultiArray(data=[time.monotonic()]))
        time.sleep(0.01)
    time.sleep(0.2)
    with client.lock:
        return list(client.pings)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=60)
    args = parser.parse_args()
    domain = claim_domain_id()
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    logs = Path("/tmp") / f"ros2_control_latency_{domain}"
    logs.mkdir(exist_ok=True)
    with ros_session(domain_id=domain) as context, Spinner(context) as spinner:
        node = Node("latency_client", context=context)
        client = Client(node)
        spinner.add_node(node)
        robot = _start(ROBOT, env, logs / "robot")
        time.sleep(15.0)
        real = _start(REAL, env, logs / "real")
        try:
            _wait(lambda: client.spec is not None and client.commands, 120.0, "deploy real")
            time.sleep(2.0)
            assert client.spec is not None
            hold = np.array(client.spec.position, dtype=np.float64)
            latencies = [
                _trial(client, hold, 1.0 if i % 2 == 0 else -1.0) for i in range(args.trials)
            ]
            hops = _hops(client, 200)
        finally:
            for process in (real, robot):
                process.terminate()
                process.wait(30)
        node.destroy_node()  # type: ignore[no-untyped-call]
        rclpy.shutdown(context=context) if context.ok() else None
    _report([x for x in latencies if x is not None], args.trials, hops)


def _start(command: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
    out = log.with_suffix(".log").open("w")
    return subprocess.Popen(command, env=env, stdout=out, stderr=subprocess.STDOUT)


def _report(latencies: list[float], trials: int, hops: list[float]) -> None:
    total = np.array(latencies) * 1000
    hop = np.array(hops) * 1000
    added = total - 2 * float(np.median(hop))
    table = Table(title="policy action → robot driver's command (ms; 100 Hz, on this machine)")
    for column in ("path", "n", "median", "p95", "max"):
        table.add_column(column, justify="left" if column == "path" else "right")
    for name, values in (("one DDS hop (floor)", hop), ("action → command", total),
                         ("added (less two hops)", added)):  # fmt: skip
        table.add_row(name, str(len(values)), f"{np.median(values):.2f}",
                      f"{np.percentile(values, 95):.2f}", f"{values.max():.2f}")  # fmt: skip
    Console().print(table)
    line_ok = bool(np.median(added) <= PERIOD_S * 1000)
    p95_ok = bool(np.percentile(added, 95) <= PERIOD_S * 1000)
    print(
        f"answered {len(latencies)}/{trials}; added latency ≤ one period (10 ms): median "
        f"{line_ok}, p95 {p95_ok}. Floor of a driver that writes once per reading: the wait "
        "for the next reading, uniform over a period (median 5 ms, p95 9.5 ms)"
    )
    path = write_results(
        "ros2_control_latency",
        {
            "trials": trials,
            "answered": len(latencies),
            "hop_ms": {"median": float(np.median(hop)), "p95": float(np.percentile(hop, 95))},
            "action_to_command_ms": {
                "median": float(np.median(total)),
                "p95": float(np.percentile(total, 95)),
                "max": float(total.max()),
            },
            "added_ms": {
                "median": float(np.median(added)),
                "p95": float(np.percentile(added, 95)),
                "max": float(added.max()),
            },
            "period_ms": PERIOD_S * 1000,
            "line_met_median": line_ok,
            "line_met_p95": p95_ok,
        },
    )
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
