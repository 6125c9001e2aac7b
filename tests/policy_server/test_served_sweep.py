"""A policy served from a venv of its own (numpy, msgpack, websockets and the serving
helper; no openral) sweeps 10 seeds with the same trajectory digests as the same class
in-process; a server that is down, or a served policy that answers a wrong width or NaN,
is one line per episode and the sweep finishes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO, ROBOTS
from tests.policy_server.test_policy_server import _free_port

OPENRAL = REPO / ".venv" / "bin" / "openral"
UV = REPO / ".tools" / "venv" / "bin" / "uv"
POLICIES = Path(__file__).with_name("served_policies.py")
SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
PINS = (f"numpy=={np.__version__}", "msgpack==1.2.4", "websockets==17.4")


@pytest.fixture(scope="module")
def policy_python(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A venv's python with the serving helper and its three dependencies, no openral."""
    venv = tmp_path_factory.mktemp("policy-venv") / "venv"
    subprocess.run([str(UV), "venv", "--quiet", "--python", sys.executable, str(venv)], check=True)
    python = venv / "bin" / "python"
    helper = REPO / "libs" / "policy_server"
    install = [str(UV), "pip", "install", "--quiet", "--python", str(python), *PINS, str(helper)]
    subprocess.run(install, check=True, timeout=300)
    probe = subprocess.run([str(python), "-c", "import openral_core"], capture_output=True)
    assert probe.returncode != 0  # no openral in there
    return python


@pytest.fixture
def served(policy_python: Path) -> Iterator[tuple[str, str]]:
    """Serve a class of served_policies.py from the venv: yields a function of the class
    name that returns the address."""
    running: list[subprocess.Popen[str]] = []

    def serve(name: str) -> str:
        port = _free_port()
        command = [str(policy_python), "-m", "openral_policy_server"]
        command += [f"{POLICIES}:{name}", "--port", str(port)]
        server = subprocess.Popen(command, stdout=subprocess.PIPE, text=True)
        running.append(server)
        assert server.stdout is not None
        line = server.stdout.readline()  # printed once it listens
        assert line.startswith("serving "), line
        return f"ws://127.0.0.1:{port}"

    yield serve  # type: ignore[misc]
    for server in running:
        server.terminate()
        server.wait(10)


def _sweep(policy: str, out: Path, seeds: str = "0:10", *more: str) -> tuple[int, list[dict]]:
    command = [str(OPENRAL), "sim", "sweep", "--config", str(SCENE), "--seeds", seeds]
    command += ["--policy", policy, "--steps", "30", "--workers", "2", "--out", str(out), *more]
    env = {**os.environ, "COLUMNS": "400"}
    done = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
    assert "Traceback" not in done.stderr, done.stderr
    lines = (out / "episodes.jsonl").read_text().splitlines()
    return done.returncode, sorted((json.loads(line) for line in lines), key=lambda r: r["seed"])


def test_a_policy_served_from_its_own_venv_sweeps_like_the_same_class_in_process(
    served, tmp_path: Path
) -> None:
    address = served("Swirl")
    code, remote = _sweep(address, tmp_path / "remote")
    assert code == 0 and len(remote) == 10
    assert all(row["error"] is None and row["steps"] == 30 for row in remote), remote
    _, local = _sweep(f"{POLICIES}:Swirl", tmp_path / "local")
    assert [row["trajectory_sha256"] for row in remote] == [
        row["trajectory_sha256"] for row in local
    ]
    assert len({row["trajectory_sha256"] for row in remote}) == 10  # task state travelled


def test_a_server_down_or_answering_nonsense_is_one_line_per_episode(
    served, tmp_path: Path
) -> None:
    started = time.monotonic()
    code, down = _sweep(f"ws://127.0.0.1:{_free_port()}", tmp_path / "down", "0:3")
    assert code == 1 and len(down) == 3  # every episode failed: exit 1, as for any policy
    assert all("is not reachable (ConnectionRefusedError" in row["error"] for row in down)
    assert time.monotonic() - started < 120
    for name, said in (("WrongWidth", "action has 3 values"), ("NotANumber", "is nan")):
        code, rows = _sweep(served(name), tmp_path / name, "0:2")
        assert code == 1 and all(said in row["error"] for row in rows), rows


def test_a_policy_file_is_executed_again_in_each_forked_worker(tmp_path: Path) -> None:
    """The sweep executes the file in this process first (its fit check), then forks its
    workers: each must execute it again, so what it opens at import is its own."""
    code, rows = _sweep(f"{POLICIES}:OpenedHere", tmp_path / "out", "0:4")
    assert code == 0 and all(row["error"] is None for row in rows), rows


def test_rskill_run_drives_deploy_sim_with_a_policy_served_from_its_own_venv(
    served, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``rskill run --policy ws://…`` against a live deploy sim: the graph's observation
    (joints, TCP, and both cameras by slot once their first frames came: the policy needs
    none to begin) goes to the served policy, and each of its answers is one action on
    ``/openral/safe_action``."""
    from openral_nodes.runtime import claim_domain_id

    from tests.ros.lifecycle_client import deploy_output, deploy_sim

    log = tmp_path / "seen.jsonl"
    monkeypatch.setenv("OPENRAL_TEST_SWAY_LOG", str(log))  # the server inherits it
    address, domain = served("SwayLogged"), claim_domain_id()
    with deploy_sim(SCENE, domain, tmp_path) as process:
        runner = subprocess.run(
            [str(OPENRAL), "rskill", "run", "--robot", "franka_panda", "--policy", address,
             "--duration", "3", "--domain-id", str(domain)],
            capture_output=True, text=True, timeout=180, env={**os.environ, "COLUMNS": "400"},
        )  # fmt: skip
        assert runner.returncode == 0, (runner.stderr, deploy_output(tmp_path))
        assert process.poll() is None
    said = runner.stdout.strip().splitlines()[-1]
    assert said.startswith(f"{address} on franka_panda: "), said
    actions = int(said.split(": ")[1].split(" action")[0])
    seen = [json.loads(line) for line in log.read_text(encoding="utf-8").splitlines()]
    assert actions >= 10 and len(seen) == actions, (said, len(seen))
    shown = {"observation.state", "observation.velocity", "observation.tcp_pose"}
    shown |= {"observation.images.camera1", "observation.images.camera2", "action_spec"}
    first = next(i for i, keys in enumerate(seen) if shown <= set(keys))  # frames come later
    assert all(shown <= set(keys) for keys in seen[first:]), seen  # and are never dropped
    assert first < len(seen) / 2, (first, len(seen))
