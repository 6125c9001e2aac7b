"""Does ``openral deploy sim`` run in real time? Simulated against wall time, and rates.

Launches ``openral deploy sim`` on the Panda tabletop as a subprocess on a ROS domain of its
own, with a copy of the Panda manifest whose two cameras run at different rates (15 Hz and
5 Hz by default), and watches it from this process as an outside subscriber would. Phases,
each ``--seconds`` long:

- ``idle``: nobody sends actions;
- ``rskill 10 Hz`` and ``rskill 40 Hz``: ``openral rskill run`` streams the wave policy;
- ``flood``: this process publishes the hold action as fast as it can (10 s).

Per phase: simulated seconds per wall second from ``/clock`` and from the ``/joint_states``
stamps (1.00 = real time), the ``/joint_states`` rate against its 50 Hz, and each camera's
rate against its manifest rate. Run with ``just bench-realtime``; the table is printed and
written to ``benchmarks/results/real_time.json``.
"""

from __future__ import annotations

import argparse
import subprocess
import tempfile
import threading
import time
from functools import partial
from pathlib import Path
from typing import Any

from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.node import Node
from rich.console import Console
from rich.table import Table
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import Float64MultiArray

from benchmarks.deploy_launch import (
    DEFAULT_SCENE,
    OPENRAL,
    REPO,
    Launch,
    camera_topic,
    deploy_env,
    received_rate,
)
from benchmarks.results_file import write_results

MANIFEST = REPO / "robots" / "franka_panda" / "robot.yaml"
STATE_HZ = 50.0
TARGETS = {"real_time": 0.01, "state_rate": 0.02, "camera_rate": 0.05}
"""Largest relative error of simulated-over-wall time, /joint_states rate, camera rates."""
Sample = tuple[float, float]
"""(arrival on the wall clock [s], header stamp [s])."""


def manifest_with_rates(folder: Path, rates: dict[str, float]) -> Path:
    """A copy of the Panda manifest in ``folder/franka_panda`` whose cameras run at
    ``rates`` (sensor name → Hz)."""
    text = MANIFEST.read_text()
    for name, rate in rates.items():
        start = text.index(f"  - name: {name}\n")
        at = text.index("rate_hz: 10.0", start)
        text = text[:at] + f"rate_hz: {rate}" + text[at + len("rate_hz: 10.0") :]
    target = folder / "franka_panda" / "robot.yaml"
    target.parent.mkdir(parents=True)
    target.write_text(text)
    return target


def _stamp(msg: Any) -> float:
    stamp = msg.clock if isinstance(msg, Clock) else msg.header.stamp
    return float(stamp.sec + stamp.nanosec * 1e-9)


class Recorder:
    """Arrival times and stamps of /clock, /joint_states and the camera images."""

    def __init__(self, node: Node, cameras: list[str]) -> None:
        topics: dict[str, Any] = {"/clock": Clock, "/joint_states": JointState}
        topics |= {camera_topic(c): Image for c in cameras}
        self.samples: dict[str, list[Sample]] = {t: [] for t in topics}
        self._lock = threading.Lock()
        for topic, kind in topics.items():
            node.create_subscription(kind, topic, partial(self._on, topic), 100)

    def _on(self, topic: str, msg: Any) -> None:
        with self._lock:
            self.samples[topic].append((time.monotonic(), _stamp(msg)))

    def window(self, start: float, end: float) -> dict[str, list[Sample]]:
        """The samples that arrived within [start, end] of the wall clock."""
        with self._lock:
            return {t: [s for s in v if start <= s[0] <= end] for t, v in self.samples.items()}


def measure(samples: dict[str, list[Sample]]) -> dict[str, float]:
    """Simulated seconds per wall second (from /clock and /joint_states) and rates [Hz]."""
    result: dict[str, float] = {}
    for topic, rows in samples.items():
        result[f"{topic} rate"] = received_rate([wall for wall, _ in rows])
        if topic in ("/clock", "/joint_states") and len(rows) > 1:
            wall = rows[-1][0] - rows[0][0]
            result[f"{topic} real time"] = (rows[-1][1] - rows[0][1]) / wall
    return result


def flood(node: Node, seconds: float, hold: list[float]) -> int:
    """Publish ``hold`` on /openral/safe_action as fast as possible; returns how many."""
    publisher = node.create_publisher(Float64MultiArray, "/openral/safe_action", 10)
    sent, end = 0, time.monotonic() + seconds
    while time.monotonic() < end:
        publisher.publish(Float64MultiArray(data=hold))
        sent += 1
    node.destroy_publisher(publisher)
    return sent


def run_phases(args: argparse.Namespace, console: Console) -> list[dict[str, Any]]:
    """Launch deploy sim, run every phase, stop it; one result row per phase."""
    domain = claim_domain_id()
    env = deploy_env()
    rows = []
    with tempfile.TemporaryDirectory() as folder, ros_session(domain_id=domain) as context:
        rates = {"agentview": args.rates[0], "wrist": args.rates[1]}
        manifest = manifest_with_rates(Path(folder), rates)
        node = Node("bench_real_time", context=context)
        recorder = Recorder(node, list(rates))
        spinner = Spinner(context).start()
        spinner.add_node(node)
        command = [
            str(OPENRAL), "deploy", "sim", "--config", str(DEFAULT_SCENE),
            "--manifest", str(manifest), "--no-viewer", "--domain-id", str(domain),
        ]  # fmt: skip
        launched = time.monotonic()
        deploy = Launch(
            subprocess.Popen(
                command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env, text=True
            ),
            launched,
        )
        try:
            time.sleep(args.warmup)
            for phase in ("idle", "rskill 10 Hz", "rskill 40 Hz", "flood"):
                console.print(f"{phase} …")
                rows.append(_phase(phase, args, recorder, node, domain, env) | {"phase": phase})
        finally:
            deploy.stop()
            spinner.stop()
            node.destroy_node()  # type: ignore[no-untyped-call]
    for row in rows:
        row["camera_targets_hz"] = rates
    return rows


def _phase(
    phase: str,
    args: argparse.Namespace,
    recorder: Recorder,
    node: Node,
    domain: int,
    env: dict[str, str],
) -> dict[str, Any]:
    """One phase's measures (see the module doc)."""
    seconds = 10.0 if phase == "flood" else args.seconds
    runner = None
    if phase.startswith("rskill"):
        rate = phase.split()[1]
        runner = subprocess.Popen(
            [str(OPENRAL), "rskill", "run", "--robot", "franka_panda", "--rate", rate,
             "--duration", str(seconds + 4.0), "--domain-id", str(domain)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
        )  # fmt: skip
        time.sleep(3.0)  # its start-up and discovery, outside the window
    start = time.monotonic()
    sent = flood(node, seconds, args.hold) if phase == "flood" else 0
    time.sleep(max(0.0, start + seconds - time.monotonic()))
    result = measure(recorder.window(start, time.monotonic()))
    if runner is not None:
        runner.wait(30)
    return result | {"seconds": seconds, "flood_sent": sent}


def table_of(rows: list[dict[str, Any]]) -> Table:
    """The rows as a table, errors against TARGETS in green or red."""
    cameras = list(rows[0]["camera_targets_hz"].items())
    table = Table(title="deploy sim against the wall clock (Panda tabletop, outside subscriber)")
    for column in ("phase", "sim/wall /clock", "sim/wall stamps", "/joint_states Hz"):
        table.add_column(column, justify="left" if column == "phase" else "right")
    for name, rate in cameras:
        table.add_column(f"{name} Hz (of {rate:g})", justify="right")

    def cell(value: float, target: float, error: float) -> str:
        ok = abs(value - target) <= error * target
        return f"[{'green' if ok else 'red'}]{value:.3f}[/]"

    for row in rows:
        table.add_row(
            row["phase"],
            cell(row.get("/clock real time", 0.0), 1.0, TARGETS["real_time"]),
            cell(row.get("/joint_states real time", 0.0), 1.0, TARGETS["real_time"]),
            cell(row["/joint_states rate"], STATE_HZ, TARGETS["state_rate"]),
            *(cell(row[f"{camera_topic(n)} rate"], r, TARGETS["camera_rate"]) for n, r in cameras),
        )
    return table


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=60.0, help="length of each phase [s]")
    parser.add_argument("--warmup", type=float, default=6.0, help="start-up before idle [s]")
    parser.add_argument(
        "--rates", type=float, nargs=2, default=[15.0, 5.0], help="agentview, wrist rates [Hz]"
    )
    args = parser.parse_args()
    args.hold = [0.0, 0.0, 0.0, -1.57079, 0.0, 1.57079, -0.7853, 1.0]  # the Panda's hold
    console = Console()
    rows = run_phases(args, console)
    console.print(table_of(rows))
    path = write_results("real_time", {"seconds": args.seconds, "phases": rows})
    console.print(f"Written to {path}.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
