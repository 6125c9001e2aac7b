"""Launching ``openral deploy sim`` from a benchmark and watching it from the outside.

Shared by ``bench-deploy`` (start-up) and ``bench-camera`` (CPU and camera rates): each
launch runs on a ROS domain of its own (:func:`~openral_nodes.runtime.claim_domain_id`), a
:class:`Watcher` in the benchmark's process records when joint states and camera frames
arrive (serialized, never converted to Python messages, so watching costs little), and
CPU time is read from ``/proc`` for the command and every live descendant.

Discovery: FastDDS re-announces a participant every 3 s after its first burst, and a
freshly launched command often learns of a watcher that has been up for a while only at the
watcher's next announcement (the first message then arrived at a fixed watcher age, up to
~3 s late, whatever the command did). The watcher therefore announces itself every 0.1 s
(:data:`WATCHER_PROFILE`); the launched command keeps the default discovery.

Bytecode: a user's install keeps compiled ``.pyc`` files. A shell with
``PYTHONDONTWRITEBYTECODE`` set (as some sandboxes and CI images do) would make every
launch compile the whole import tree again (~0.9 s here), so :func:`deploy_env` gives the
launched commands a bytecode cache of their own in the temp dir and :func:`warm_up` fills
it with one untimed launch.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import Any

from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.node import Node
from sensor_msgs.msg import Image, JointState

REPO = Path(__file__).resolve().parent.parent
DEFAULT_SCENE = REPO / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
OPENRAL = Path(sys.executable).parent / "openral"
PYCACHE = Path(tempfile.gettempdir()) / "openral-bench-pycache"
MODEL_CACHE = Path(tempfile.gettempdir()) / "openral-bench-models"
"""Compiled-model cache of the launched commands (``OPENRAL_MODEL_CACHE``), unless the shell
names one: the benchmarks neither depend on nor fill the user's."""
"""Bytecode cache of launched commands when the shell disables writing bytecode."""
PROFILE_VARIABLE = "FASTRTPS_DEFAULT_PROFILES_FILE"
WATCHER_PROFILE = Path(tempfile.gettempdir()) / "openral-bench-watcher.xml"
"""FastDDS profile of the watcher's participant: a 0.1 s announcement period."""
WATCHER_PROFILE_XML = """<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name="openral_bench_watcher" is_default_profile="true">
    <rtps><builtin><discovery_config><leaseAnnouncement>
      <sec>0</sec><nanosec>100000000</nanosec>
    </leaseAnnouncement></discovery_config></builtin></rtps>
  </participant>
</profiles>
"""
WATCHER_SETTLE_S = 1.5
"""Pause between starting the watcher's participant and launching the command [s]."""
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
JOINT_STATES = "/joint_states"


def camera_topic(camera: str) -> str:
    """The image topic ``openral deploy sim`` publishes for ``camera``."""
    return f"/openral/cameras/{camera}/image"


def stat_cpu_ticks(stat: str) -> int:
    """utime + stime + cutime + cstime of one ``/proc/<pid>/stat`` line [clock ticks]: the
    process's own CPU (all threads) and that of its children it has waited for."""
    fields = stat.rsplit(")", 1)[1].split()  # the command name may hold spaces and ")"
    return sum(int(value) for value in fields[11:15])


def descendants(pid: int) -> list[int]:
    """``pid`` and every live process below it (from ``/proc/<pid>/task/*/children``)."""
    found, queue = [], [pid]
    while queue:
        current = queue.pop()
        found.append(current)
        for task in Path(f"/proc/{current}/task").glob("*"):
            try:
                queue.extend(int(child) for child in (task / "children").read_text().split())
            except OSError:  # the task ended while we looked
                continue
    return found


def tree_cpu_seconds(pid: int) -> float:
    """CPU time (user + system, all threads) of ``pid`` and its descendants so far [s]."""
    ticks = 0
    for process in descendants(pid):
        try:
            ticks += stat_cpu_ticks(Path(f"/proc/{process}/stat").read_text())
        except OSError:  # ended between listing and reading
            continue
    return ticks / CLOCK_TICKS


def received_rate(arrivals: list[float]) -> float:
    """Messages per second between the first and the last arrival [Hz] (nan under two)."""
    if len(arrivals) < 2 or arrivals[-1] <= arrivals[0]:
        return float("nan")
    return (len(arrivals) - 1) / (arrivals[-1] - arrivals[0])


class Watcher:
    """Records arrival times (``time.monotonic``) of joint states and camera frames, and the
    CPU time the watched process had used when each topic's first message arrived."""

    def __init__(
        self, node: Node, cameras: list[str], extra: Mapping[str, type[Any]] | None = None
    ) -> None:
        """Watch ``/joint_states``, each camera's image and each ``extra`` topic (name →
        message class)."""
        self.pid: int | None = None
        """The watched process (set after launching it)."""
        self.first_cpu_s: dict[str, float] = {}
        """CPU time of :attr:`pid` and its descendants at each topic's first arrival [s]."""
        self.arrivals: dict[str, list[float]] = {JOINT_STATES: []}
        node.create_subscription(
            JointState, JOINT_STATES, partial(self._on, JOINT_STATES), 50, raw=True
        )
        topics: dict[str, type[Any]] = {camera_topic(camera): Image for camera in cameras}
        for topic, kind in {**topics, **(extra or {})}.items():
            self.arrivals[topic] = []
            node.create_subscription(kind, topic, partial(self._on, topic), 50, raw=True)
        self.changed = threading.Condition()

    def _on(self, topic: str, _msg: Any) -> None:
        with self.changed:
            self.arrivals[topic].append(time.monotonic())
            if self.pid is not None and topic not in self.first_cpu_s:
                self.first_cpu_s[topic] = tree_cpu_seconds(self.pid)
            self.changed.notify_all()

    def wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Block until ``predicate()`` holds (checked on every arrival) or ``timeout_s``."""
        with self.changed:
            return self.changed.wait_for(predicate, timeout_s)

    def reset(self) -> None:
        """Forget every arrival so far."""
        with self.changed:
            for arrivals in self.arrivals.values():
                arrivals.clear()

    def snapshot(self) -> dict[str, list[float]]:
        """A copy of the arrivals so far, by topic."""
        with self.changed:
            return {topic: list(times) for topic, times in self.arrivals.items()}


def deploy_env(**extra: str) -> dict[str, str]:
    """The environment of a launched command: EGL, localhost discovery, and a bytecode cache
    of its own when this shell disables writing bytecode (see the module doc)."""
    env = {**os.environ, "MUJOCO_GL": "egl", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    if env.get(PROFILE_VARIABLE) == str(WATCHER_PROFILE):  # the watcher's, not the command's
        del env[PROFILE_VARIABLE]
    if env.pop("PYTHONDONTWRITEBYTECODE", None) is not None or sys.dont_write_bytecode:
        env["PYTHONPYCACHEPREFIX"] = str(PYCACHE)
    env.setdefault("OPENRAL_MODEL_CACHE", str(MODEL_CACHE))
    return {**env, **extra}


def warm_up(scene: Path) -> float:
    """One untimed ``deploy sim --duration 0`` (bytecode cache and OS file cache); its wall
    time [s]."""
    start = time.monotonic()
    command = [str(OPENRAL), "deploy", "sim", "--config", str(scene), "--no-viewer"]
    domain = claim_domain_id()
    subprocess.run(
        [*command, "--duration", "0", "--domain-id", str(domain)],
        env=deploy_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        check=True,
    )
    return time.monotonic() - start


class Launch:
    """One launched process: when it started, its output lines, and when it printed the line
    that says it is up (``running`` for ``deploy sim``)."""

    def __init__(
        self, process: subprocess.Popen[str], launched: float, marker: str = "running"
    ) -> None:
        self.process = process
        self.launched = launched
        """``time.monotonic()`` just before ``Popen``."""
        self.marker = marker
        self.lines: list[str] = []
        """Every line it printed so far."""
        self.active: list[float] = []
        """When it printed a line starting with ``marker`` (empty until then)."""
        self.exit_code: int | None = None
        """Set by :meth:`stop`."""
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        """Keep every line; note when the ``marker`` line came."""
        assert self.process.stdout is not None
        for line in self.process.stdout:
            if line.startswith(self.marker) and not self.active:
                self.active.append(time.monotonic())
            self.lines.append(line.rstrip("\n"))

    def wait_active(self, timeout_s: float) -> bool:
        """Block until the ``marker`` line was printed (polled every 10 ms) or ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while not self.active and time.monotonic() < deadline and self.process.poll() is None:
            time.sleep(0.01)
        return bool(self.active)

    def stop(self) -> int:
        """SIGINT (the command's own clean shutdown), then its exit code (killed after 30 s)."""
        self.process.send_signal(signal.SIGINT)
        try:
            self.exit_code = self.process.wait(30)
        finally:
            self.process.kill()
            self._reader.join(5)
        return self.exit_code


@contextmanager
def watched_deploy(
    scene: Path,
    cameras: list[str],
    *options: str,
    env: Mapping[str, str] | None = None,
    extra: Mapping[str, type[Any]] | None = None,
) -> Iterator[tuple[Launch, Watcher]]:
    """Launch ``openral deploy sim`` on a fresh domain with a :class:`Watcher` on it; stop it
    (SIGINT) when the block ends. ``options`` are extra command-line options, ``env`` extra
    environment variables, ``extra`` more topics to watch (name → message class)."""
    domain = claim_domain_id()
    if PROFILE_VARIABLE not in os.environ:  # a profile of the user's own is left alone
        WATCHER_PROFILE.write_text(WATCHER_PROFILE_XML)
        os.environ[PROFILE_VARIABLE] = str(WATCHER_PROFILE)
    with ros_session(domain_id=domain) as context, Spinner(context) as spinner:
        node = Node("bench_watcher", context=context)
        watcher = Watcher(node, cameras, extra)
        spinner.add_node(node)
        command = [str(OPENRAL), "deploy", "sim", "--config", str(scene), "--no-viewer"]
        command += [*options, "--domain-id", str(domain)]
        # A watcher that is itself still announcing its participant can make the first match
        # ~1.8 s late (2 of 5 runs here); a real second terminal is long settled, so settle.
        time.sleep(WATCHER_SETTLE_S)
        launched = time.monotonic()
        process = subprocess.Popen(
            command,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env=deploy_env(**(env or {})),
            text=True,
        )
        watcher.pid = process.pid
        launch = Launch(process, launched)
        try:
            yield launch, watcher
        finally:
            launch.stop()
            spinner.stop()
            node.destroy_node()  # type: ignore[no-untyped-call]
