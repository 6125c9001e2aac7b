"""The sweep machinery: intervals, seeds, the results file, the executors, the CLI.

- Wilson intervals match published values and stay inside [0, 1];
- ``episodes.jsonl`` survives a cut-off last line, ``--resume`` keeps every written line
  byte for byte and runs only what is missing, and the finished file is in plan order;
- serial, a 2-process pool and Ray (2 CPUs) give identical files except wall times;
- an episode that raises is a line with its error, and the sweep goes on;
- a sweep killed half-way and resumed ends with every episode exactly once.
"""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest
from openral_cli.optional_values import with_optional_values
from openral_eval import policies
from openral_eval.episode import EpisodeResult, EpisodeSpec, run_episode
from openral_eval.results import EpisodeLog
from openral_eval.summary import wilson

from benchmarks.ray_head import RayHead, ray_head
from tests.conftest import ROBOTS
from tests.eval.processes import alive, children

SCENE = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
OPENRAL = Path(sys.executable).parent / "openral"
SWEEP = [
    "sim",
    "sweep",
    "--config",
    SCENE,
    "--policy",
    "wave",
    "-p",
    "required_slots=",
    "--steps",
    "8",
]


@pytest.mark.parametrize(
    ("k", "n", "low", "high"),
    [
        (0, 10, 0.0, 0.2775),
        (10, 10, 0.7225, 1.0),
        (5, 10, 0.2366, 0.7634),
        (18, 20, 0.6990, 0.9721),
    ],
)
def test_wilson_interval_matches_published_values(k: int, n: int, low: float, high: float) -> None:
    assert wilson(k, n) == pytest.approx((low, high), abs=5e-4)


def test_ray_alone_means_a_local_instance() -> None:
    assert with_optional_values(["sim", "sweep", "--ray"]) == ["sim", "sweep", "--ray", "local"]
    assert with_optional_values(["--ray", "--out", "o"]) == ["--ray", "local", "--out", "o"]
    assert with_optional_values(["--ray", "10.0.0.2:6379"]) == ["--ray", "10.0.0.2:6379"]


def _lines(path: Path) -> list[dict[str, object]]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def _without_wall_time(path: Path) -> list[dict[str, object]]:
    return [{k: v for k, v in line.items() if k != "wall_time_s"} for line in _lines(path)]


def _sweep(out: Path, *extra: str, seeds: str = "0:4") -> subprocess.CompletedProcess[str]:
    command = [str(OPENRAL), *SWEEP, "--seeds", seeds, "--video", "none", "--out", str(out), *extra]
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def cluster() -> Iterator[RayHead]:
    """A running Ray instance of 2 CPUs that tests join by address (it starts while the
    first test using it runs its local sweeps)."""
    with ray_head(2) as head:
        yield head


def test_serial_pool_ray_and_a_joined_ray_cluster_write_the_same_file(
    tmp_path: Path, cluster: RayHead
) -> None:
    runs = {
        "serial": ("--workers", "1"),
        "pool": ("--workers", "2"),
        "ray": ("--workers", "2", "--ray"),
        "joined": ("--ray", "ADDRESS"),
    }
    for name, extra in runs.items():
        args = [cluster.address if arg == "ADDRESS" else arg for arg in extra]
        result = _sweep(tmp_path / name, *args)
        assert result.returncode == 0, result.stderr
    serial = _without_wall_time(tmp_path / "serial" / "episodes.jsonl")
    assert [line["seed"] for line in serial] == [0, 1, 2, 3]
    assert all(line["trajectory_sha256"] and line["error"] is None for line in serial)
    for name in ("pool", "ray", "joined"):
        assert _without_wall_time(tmp_path / name / "episodes.jsonl") == serial, name
        times = json.loads((tmp_path / name / "summary.json").read_text())
        assert times["startup_s"] + times["episodes_wall_s"] == pytest.approx(
            times["run_wall_s"], abs=2e-3
        )
        assert times["startup_s"] > 0.0 and times["episodes_wall_s"] > 0.0


def test_a_cut_off_line_is_dropped_and_resume_keeps_every_written_line(tmp_path: Path) -> None:
    log = EpisodeLog(tmp_path / "episodes.jsonl")
    log.start(resume=False)
    specs = [EpisodeSpec(SCENE, seed, "wave", (("required_slots", ""),), 4) for seed in range(3)]
    for spec in specs[:2]:
        log.append(run_episode(spec))
    written = log.path.read_bytes()
    with log.path.open("ab") as file:
        file.write(b'{"scene": "cut off by a ki')
    assert set(log.done()) == {specs[0].key, specs[1].key}
    log.start(resume=True)
    assert log.path.read_bytes() == written
    log.append(run_episode(specs[2]))
    assert [line["seed"] for line in log.sort(reversed(specs))] == [2, 1, 0]


def test_an_episode_that_raises_is_recorded_and_the_sweep_goes_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    class Broken:
        required_slots: tuple[str, ...] = ()
        needs_privileged = False

        def act(self, obs: policies.Observation) -> object:
            raise RuntimeError("the policy fell over")

    entry = policies.PolicyEntry(policies.WaveConfig, lambda config: Broken())
    monkeypatch.setitem(policies.POLICIES, "broken", entry)
    result = run_episode(EpisodeSpec(SCENE, 0, "broken", (), 5))
    assert not result.success and result.steps == 0
    assert result.error is not None and result.error.startswith(
        "RuntimeError: the policy fell over"
    )


@pytest.mark.parametrize("stop", [signal.SIGKILL, signal.SIGINT], ids=["SIGKILL", "SIGINT"])
def test_a_killed_sweep_resumed_runs_every_episode_once(
    tmp_path: Path, stop: signal.Signals
) -> None:
    out = tmp_path / "killed"
    command = [str(OPENRAL), *SWEEP, "--seeds", "0:8", "--workers", "2", "--video", "none"]
    command[command.index("--steps") + 1] = "800"  # long enough episodes to kill half-way
    process = subprocess.Popen(
        [*command, "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    log = out / "episodes.jsonl"
    deadline = time.monotonic() + 300
    while (
        not log.exists() or len(log.read_text().splitlines()) < 3
    ) and time.monotonic() < deadline:
        time.sleep(0.02)
    workers = children(process.pid)
    assert len(workers) == 2
    process.send_signal(stop)
    _, stderr = process.communicate(timeout=60)
    gone = time.monotonic() + 1.0  # the workers die with the sweep, not after their episode
    while any(alive(pid) for pid in workers) and time.monotonic() < gone:
        time.sleep(0.02)
    assert not any(alive(pid) for pid in workers)
    if stop == signal.SIGINT:  # one line, no traceback, the conventional status
        assert process.returncode == 130
        assert "Traceback" not in stderr
        assert re.search(r"interrupted: \d+ of 8 episodes are in .*--resume runs the rest", stderr)
    before = log.read_text().splitlines()
    assert 3 <= len(before) < 8, "kill the sweep half-way"
    again = subprocess.run(
        [*command, "--out", str(out), "--resume"], capture_output=True, text=True, timeout=600
    )
    assert again.returncode == 0, again.stderr
    after = log.read_text().splitlines()
    seeds = [json.loads(line)["seed"] for line in after]
    assert seeds == list(range(8))
    assert set(before) <= set(after)  # every line written before the kill, byte for byte
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenes"][0]["episodes"] == 8


def test_results_already_there_need_resume(tmp_path: Path) -> None:
    assert _sweep(tmp_path, seeds="0:1").returncode == 0
    again = _sweep(tmp_path, seeds="0:1")
    assert again.returncode == 1
    assert "already holds results: add --resume" in again.stderr
    bad = _sweep(tmp_path / "bad", seeds="5:2")
    assert bad.returncode == 2 and "is an empty range" in bad.stderr


def _free_port() -> int:
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.mark.parametrize(
    ("address", "expected"),
    [
        (f"127.0.0.1:{_free_port()}", "nothing answers (Connection refused)"),
        ("no-port-here", "expected 'local', 'auto' or a cluster's HOST:PORT"),
    ],
    ids=["free-port", "no-port"],  # the same in every process (the port is not)
)
def test_a_ray_address_where_nothing_answers_is_one_line_at_once(
    tmp_path: Path, address: str, expected: str
) -> None:
    started = time.monotonic()
    result = _sweep(tmp_path / "out", "--ray", address, seeds="0:1")
    assert result.returncode == 1
    assert expected in result.stderr and "Traceback" not in result.stderr
    assert time.monotonic() - started < 60  # Ray's own join retries for over ten minutes
    assert not (tmp_path / "out" / "episodes.jsonl").exists()


def test_run_wall_time_counts_the_episodes_not_the_start_up(tmp_path: Path) -> None:
    started = time.monotonic()
    assert _sweep(tmp_path, "--workers", "1", seeds="0:2").returncode == 0
    command_s = time.monotonic() - started
    summary = json.loads((tmp_path / "summary.json").read_text())
    episodes_s = sum(line["wall_time_s"] for line in _lines(tmp_path / "episodes.jsonl"))
    assert episodes_s <= summary["episodes_wall_s"] <= summary["run_wall_s"] < command_s


@pytest.mark.parametrize(
    ("where", "gave_up"),
    [
        ("pool", "its worker process died, every time it ran"),
        ("ray", "Ray gave up on it: WorkerCrashedError"),
    ],
)
def test_a_dead_worker_costs_only_its_episode_which_is_retried_then_recorded(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    cluster: RayHead,
    where: str,
    gave_up: str,
) -> None:
    import os

    from openral_eval import sweep

    marker = tmp_path / "seed0-died-once"

    def dying(spec: EpisodeSpec) -> EpisodeResult:  # forked, or pickled by value into Ray
        if spec.seed == 1 or (spec.seed == 0 and not marker.exists()):
            marker.touch()
            os._exit(3)  # the worker process dies, as on a segfault
        return run_episode(spec)

    monkeypatch.setattr(sweep, "run_episode", dying)
    specs = [EpisodeSpec(SCENE, seed, "wave", (("required_slots", ""),), 5) for seed in range(4)]
    results: list[EpisodeResult] = []
    if where == "pool":
        sweep.run_pool(specs, 2, results.append)
    else:
        monkeypatch.delenv("RAY_AUTH_MODE", raising=False)  # the join may set it
        sweep.run_ray(specs, cluster.address, 2, results.append)
    by_seed = {result.seed: replace(result, wall_time_s=0.0) for result in results}
    assert sorted(by_seed) == [0, 1, 2, 3]  # each exactly once
    assert by_seed[0] == replace(run_episode(specs[0]), wall_time_s=0.0)  # the retry ran it
    assert by_seed[1].error == gave_up
    for seed in (2, 3):  # running beside the dying ones, never lost with them
        assert by_seed[seed] == replace(run_episode(specs[seed]), wall_time_s=0.0)
