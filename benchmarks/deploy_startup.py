"""``openral deploy sim`` from launch to live graph: first joint state, first frames, rate, CPU.

Each run launches ``openral deploy sim --no-viewer`` as a subprocess on a ROS domain of its
own and watches it from this process: the time from ``Popen`` to the first ``/joint_states``
and to the first image of every camera, then the camera rate over a sustained window
(arrival times at the subscriber) and the deploy process's CPU use over the same window
(``/proc/<pid>/stat``; 100 % = one core). Run with ``just bench-deploy``; the table is printed
and written to ``benchmarks/results/deploy_startup.json``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

from openral_core.loader import load_scene
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.node import Node
from rich.console import Console
from rich.table import Table
from sensor_msgs.msg import Image, JointState

from benchmarks.results_file import write_results

REPO = Path(__file__).resolve().parent.parent
DEFAULT_SCENE = REPO / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
OPENRAL = Path(sys.executable).parent / "openral"
TARGETS = {"first_state_s": 2.0, "first_frame_s": 4.0, "rate_error": 0.05}
"""Launch → first /joint_states [s], launch → first frame of every camera [s], and the
largest relative camera-rate error over the window."""
BOOT_TIMEOUT_S = 60.0
WATCHER_SETTLE_S = 1.5
"""Pause between starting the watcher's participant and launching the command [s]."""
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
Run = dict[str, Any]
"""One launch's measures, as ``one_run`` returns them and the JSON stores them."""


def camera_topic(camera: str) -> str:
    """The image topic ``openral deploy sim`` publishes for ``camera``."""
    return f"/openral/cameras/{camera}/image"


class Watcher:
    """Records arrival times of joint states and camera frames on one domain."""

    def __init__(self, node: Node, cameras: list[str]) -> None:
        self.arrivals: dict[str, list[float]] = {"/joint_states": []}
        node.create_subscription(
            JointState, "/joint_states", partial(self._on, "/joint_states"), 50
        )
        for camera in cameras:
            topic = camera_topic(camera)
            self.arrivals[topic] = []
            node.create_subscription(Image, topic, partial(self._on, topic), 50)
        self.changed = threading.Condition()

    def _on(self, topic: str, _msg: Any) -> None:
        with self.changed:
            self.arrivals[topic].append(time.monotonic())
            self.changed.notify_all()

    def wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        with self.changed:
            return self.changed.wait_for(predicate, timeout_s)

    def reset(self) -> None:
        with self.changed:
            for arrivals in self.arrivals.values():
                arrivals.clear()


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a live process (all threads) [s]."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def _watch_stdout(process: subprocess.Popen[str], active: list[float]) -> None:
    """Note when the command reports its node active; drain the rest of its output."""
    assert process.stdout is not None
    for line in process.stdout:
        if line.startswith("running") and not active:
            active.append(time.monotonic())


def one_run(scene: Path, cameras: list[str], window_s: float, rate_hz: float) -> Run:
    """Launch, wait for every first message, measure a window, stop with SIGINT."""
    domain = claim_domain_id()
    with ros_session(domain_id=domain) as context, Spinner(context) as spinner:
        node = Node("bench_watcher", context=context)
        watcher = Watcher(node, cameras)
        spinner.add_node(node)
        command = [
            str(OPENRAL), "deploy", "sim", "--config", str(scene), "--no-viewer",
            "--camera-rate", str(rate_hz), "--domain-id", str(domain),
        ]  # fmt: skip
        env = {**os.environ, "MUJOCO_GL": "egl", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
        # A watcher that is itself still announcing its participant can make the first match
        # ~1.8 s late (2 of 5 runs here); a real second terminal is long settled, so settle.
        time.sleep(WATCHER_SETTLE_S)
        launched = time.monotonic()
        process = subprocess.Popen(
            command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env, text=True
        )
        active: list[float] = []  # when the command printed "running" (node active)
        reader = threading.Thread(target=_watch_stdout, args=(process, active), daemon=True)
        reader.start()
        try:
            booted = watcher.wait(lambda: all(watcher.arrivals.values()), BOOT_TIMEOUT_S)
            if not booted:
                raise RuntimeError(f"no first message on every topic within {BOOT_TIMEOUT_S} s")
            firsts = {topic: times[0] - launched for topic, times in watcher.arrivals.items()}
            watcher.wait(lambda: bool(active), 5.0)
            time.sleep(1.0)  # let discovery and start-up transients pass before the window
            watcher.reset()
            cpu0, wall0 = cpu_seconds(process.pid), time.monotonic()
            time.sleep(window_s)
            cpu1, wall1 = cpu_seconds(process.pid), time.monotonic()
            counts = {t: list(a) for t, a in watcher.arrivals.items()}
        finally:
            process.send_signal(2)  # SIGINT: the command's own clean shutdown
            try:
                process.wait(30)
            finally:
                process.kill()
                reader.join(5)
        spinner.stop()
        node.destroy_node()  # type: ignore[no-untyped-call]
    rates = {}
    for topic, arrivals in counts.items():
        span = arrivals[-1] - arrivals[0] if len(arrivals) > 1 else float("nan")
        rates[topic] = (len(arrivals) - 1) / span
    return {
        "active_s": active[0] - launched if active else float("nan"),
        "first_state_s": firsts["/joint_states"],
        "first_frame_s": {t: v for t, v in firsts.items() if t != "/joint_states"},
        "rates_hz": rates,
        "cpu_percent": 100.0 * (cpu1 - cpu0) / (wall1 - wall0),
        "exit_code": process.returncode,
    }


def parse_args() -> argparse.Namespace:
    """The command line: scene, number of runs, measuring window and camera rate."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scene", type=Path, default=DEFAULT_SCENE, help="deploy-scene file")
    parser.add_argument("--runs", type=int, default=3, help="launches to time")
    parser.add_argument("--window", type=float, default=10.0, help="rate/CPU window [s]")
    parser.add_argument("--camera-rate", type=float, default=10.0, help="camera rate [Hz]")
    return parser.parse_args()


def time_runs(args: argparse.Namespace, cameras: list[str], console: Console) -> list[Run]:
    """Launch and measure ``args.runs`` times, announcing each run."""
    runs = []
    for index in range(args.runs):
        console.print(f"run {index + 1}/{args.runs} …")
        runs.append(one_run(args.scene, cameras, args.window, args.camera_rate))
    return runs


def _target_row(table: Table, label: str, values: list[float], target: float, unit: str) -> None:
    """A row of median and worst (green within ``target``, red over it) against the target."""
    worst = max(values)
    colour = "green" if worst <= target else "red"
    table.add_row(
        label,
        f"{statistics.median(values):.2f} {unit}",
        f"[{colour}]{worst:.2f} {unit}[/]",
        f"< {target:g} {unit}",
    )


def _startup_rows(table: Table, runs: list[Run], cameras: list[str]) -> None:
    """Launch to node active, to the first joint state and to each camera's first frame."""
    actives = [r["active_s"] for r in runs]
    table.add_row(
        "launch → node active (printed)",
        f"{statistics.median(actives):.2f} s",
        f"{max(actives):.2f} s",
        "",
    )
    states = [r["first_state_s"] for r in runs]
    _target_row(table, "launch → first /joint_states", states, TARGETS["first_state_s"], "s")
    for camera in cameras:
        firsts = [r["first_frame_s"][camera_topic(camera)] for r in runs]
        _target_row(table, f"launch → first {camera} frame", firsts, TARGETS["first_frame_s"], "s")


def _streaming_rows(
    table: Table, runs: list[Run], cameras: list[str], args: argparse.Namespace
) -> None:
    """Each camera's rate error over the window, the joint-state rate and the deploy CPU."""
    for camera in cameras:
        rates = [r["rates_hz"][camera_topic(camera)] for r in runs]
        worst = max(abs(x - args.camera_rate) / args.camera_rate for x in rates)
        table.add_row(
            f"{camera} rate over {args.window:g} s",
            f"{statistics.median(rates):.2f} Hz",
            f"[{'green' if worst <= TARGETS['rate_error'] else 'red'}]{100 * worst:.1f} % off[/]",
            f"± {100 * TARGETS['rate_error']:g} %",
        )
    states_hz = [r["rates_hz"]["/joint_states"] for r in runs]
    table.add_row("/joint_states rate", f"{statistics.median(states_hz):.1f} Hz", "", "")
    cpu = [r["cpu_percent"] for r in runs]
    table.add_row("deploy process CPU", f"{statistics.median(cpu):.0f} %", f"{max(cpu):.0f} %", "")


def results_table(
    args: argparse.Namespace,
    cameras: list[str],
    runs: list[Run],
    load_before: tuple[float, float, float],
) -> Table:
    """The printed summary: start-up rows, then streaming rows, median and worst of the runs."""
    load = ", ".join(f"{x:.2f}" for x in load_before)
    table = Table(
        title=f"deploy sim start-up and streaming: {args.scene.name}, {args.runs} runs",
        caption=f"load average before: {load} on {os.cpu_count()} cores",
    )
    for column in ("measure", "median", "worst", "target"):
        table.add_column(column, justify="left" if column == "measure" else "right")
    _startup_rows(table, runs, cameras)
    _streaming_rows(table, runs, cameras, args)
    return table


def save_results(
    args: argparse.Namespace, runs: list[Run], load_before: tuple[float, float, float]
) -> Path:
    """Write the settings, targets and every run to ``benchmarks/results/deploy_startup.json``."""
    scene = args.scene.relative_to(REPO) if args.scene.is_relative_to(REPO) else args.scene
    return write_results(
        "deploy_startup",
        {
            "scene": str(scene),
            "camera_rate_hz": args.camera_rate,
            "window_s": args.window,
            "cpu_count": os.cpu_count(),
            "load_average_before": load_before,
            "targets": TARGETS,
            "runs": runs,
        },
    )


def main() -> int:
    """Time the runs, print the table, write the JSON; 1 if any run did not exit cleanly."""
    args = parse_args()
    cameras = list(load_scene(args.scene).scene.cameras)
    console = Console()
    load_before = os.getloadavg()
    runs = time_runs(args, cameras, console)
    console.print(results_table(args, cameras, runs, load_before))
    path = save_results(args, runs, load_before)
    console.print(
        f"Times from Popen (includes interpreter start-up); rates from arrival times at a "
        f"subscriber in this process; CPU: 100 % = one core. Written to {path}."
    )
    return 0 if all(r["exit_code"] == 0 for r in runs) else 1


if __name__ == "__main__":
    raise SystemExit(main())
