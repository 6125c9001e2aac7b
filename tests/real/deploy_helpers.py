"""Helpers of the ``deploy real`` tests: the command as a subprocess, a probe on its
domain, camera clips for its RGB sensors."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.context import Context
from sensor_msgs.msg import Image, JointState

from tests.ros.ros_helpers import Probe

OPENRAL = Path(sys.executable).parent / "openral"
ENV = {**os.environ, "MUJOCO_GL": "egl", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
TOPICS = {
    "/joint_states": JointState,
    "/openral/manifest_joint_states": JointState,
    "/openral/cameras/front/image": Image,
}


def openral(*args: str, stdin: int | None = None) -> subprocess.Popen[str]:
    """``openral ARGS`` as a subprocess, its output captured."""
    return subprocess.Popen(
        [str(OPENRAL), *args],
        stdin=stdin,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
    )


def deploy_real(
    transport: str, calibration: Path, domain: int, *more: str
) -> subprocess.Popen[str]:
    """``openral deploy real`` of the so101 on ``transport``."""
    return openral(
        "deploy", "real", "--robot", "so101", "--transport", transport,
        "--calibration", str(calibration), "--domain-id", str(domain), *more,
    )  # fmt: skip


def stop(process: subprocess.Popen[str], timeout_s: float = 60.0) -> tuple[str, str]:
    """SIGINT, then its output (killed if it does not end)."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    try:
        return process.communicate(timeout=timeout_s)
    finally:
        process.kill()


@dataclass
class Remote:
    """A ROS domain of its own, a probe on it and its spinner (for a process started on
    that domain)."""

    domain: int
    probe: Probe
    context: Context
    spinner: Spinner


@contextmanager
def remote_graph(topics: dict[str, object] | None = None) -> Iterator[Remote]:
    """See :class:`Remote`."""
    domain = claim_domain_id()
    with ros_session(domain_id=domain) as context, Spinner(context) as spinner:
        probe = Probe(context, topics or TOPICS, name="real_probe")
        spinner.add_node(probe.node)
        yield Remote(domain, probe, context, spinner)
        spinner.stop()
        probe.node.destroy_node()


def joints_now(remote: Remote) -> dict[str, float]:
    """The newest manifest joint state, by joint."""
    msg = remote.probe.latest("/openral/manifest_joint_states")
    return dict(zip(msg.name, msg.position, strict=True))


def camera_clip(file: Path, frames: int = 20) -> Path:
    """A short MP4 (64 x 48, a brightening green) for an RGB sensor's ``file:`` device."""
    writer = cv2.VideoWriter(str(file), cv2.VideoWriter_fourcc(*"mp4v"), 10, (64, 48))
    for index in range(frames):
        frame = np.zeros((48, 64, 3), np.uint8)
        frame[:, :, 1] = 10 * index
        writer.write(frame)
    writer.release()
    return file


class RemoteBus:
    """``openral sim bus so101`` in a process of its own (as a user runs it), calibrated
    non-interactively into ``folder``; its console and its log at hand."""

    def __init__(self, folder: Path) -> None:
        self.log = folder / "bus.log"
        self.calibration = folder / "so101.json"
        self.process = openral("sim", "bus", "so101", "--log", str(self.log), stdin=subprocess.PIPE)
        assert self.process.stdout is not None
        self.path = self.process.stdout.readline().strip()
        self.process.stdout.readline()  # the summary line
        calibrate = openral(
            "robot", "calibrate", "so101", "--transport", self.path, "--non-interactive",
            "--calibration", str(self.calibration),
        )  # fmt: skip
        _, err = calibrate.communicate(timeout=60)
        assert calibrate.returncode == 0, err

    def command(self, line: str) -> str:
        """One console command and its one-line answer."""
        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(line + "\n")
        self.process.stdin.flush()
        return self.process.stdout.readline().strip()

    def lines(self, after: float = 0.0) -> list[str]:
        """Log lines stamped after ``after`` [s, system clock]."""
        text = self.log.read_text(encoding="utf-8")
        return [line for line in text.splitlines() if float(line.split(" ", 1)[0]) > after]

    def written(self, register: str, after: float = 0.0) -> list[str]:
        """Log lines that wrote ``register`` after ``after``."""
        return [
            line
            for line in self.lines(after)
            if f"SYNC_WRITE {register} " in line or f" {register}=" in line
        ]

    def close(self) -> None:
        """``quit``, then wait for the process (killed if it does not end)."""
        try:
            self.command("quit")
            self.process.communicate(timeout=30)
        finally:
            self.process.kill()
