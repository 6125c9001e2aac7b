"""One policy file, three paths, one observation: the same class runs unchanged in the
gymnasium env's loop (:func:`~openral_eval.env_policy.policy_observation`), in ``openral
sim sweep`` (with ``--dataset``) and in ``openral rskill run`` against ``openral deploy
sim``, and sees the same keys, each with the same shape and dtype; the dataset's rows hold
the joint state, velocities and TCP pose the policy saw at each step
(``tests/eval/key_spy.py`` writes what it sees)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from openral_eval.env_policy import policy_observation
from openral_eval.policies import make_policy
from openral_eval.scene_env import make_env
from openral_nodes.runtime import claim_domain_id

from tests.conftest import REPO
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import FRANKA_SCENE

OPENRAL = Path(sys.executable).parent / "openral"
SPY = f"{REPO / 'tests' / 'eval' / 'key_spy.py'}:KeySpy"
SHARED = {
    "observation.state",
    "observation.velocity",
    "observation.tcp_pose",
    "observation.images.camera1",
}
"""What every path shows the Panda with its agent-view camera (env and sweep add the
wrist's force-torque sensor; a graph carries every camera)."""


def _seen(log: Path) -> list[dict[str, object]]:
    lines = log.read_text(encoding="utf-8").splitlines()
    assert lines, f"the policy wrote nothing to {log}"
    return [json.loads(line) for line in lines]


def _env_loop(log: Path) -> None:
    spy = make_policy(SPY, {"log": str(log)})
    env = make_env(FRANKA_SCENE, sensors=("agentview", "wrist"))  # what the dataset keeps
    try:
        obs, _ = env.reset(seed=2)
        for _ in range(3):
            obs, *_ = env.step(spy.act(policy_observation(env, obs)))
    finally:
        env.close()


def _sweep(out: Path, log: Path) -> Path:
    dataset = out / "ds"
    command = [str(OPENRAL), "sim", "sweep", "--config", str(FRANKA_SCENE), "--seeds", "2:3"]
    command += ["--policy", SPY, "-p", f"log={log}", "--steps", "5", "--video", "none"]
    done = subprocess.run(
        [*command, "--out", str(out), "--dataset", str(dataset)],
        capture_output=True, text=True, timeout=600, env={**os.environ, "MUJOCO_GL": "egl"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return dataset


def _rskill(tmp: Path, log: Path) -> None:
    domain = claim_domain_id()
    with deploy_sim(FRANKA_SCENE, domain, tmp) as process:
        runner = subprocess.run(
            [str(OPENRAL), "rskill", "run", "--robot", "franka_panda", "--policy", SPY,
             "-p", f"log={log}", "--duration", "3", "--domain-id", str(domain)],
            capture_output=True, text=True, timeout=180,
        )  # fmt: skip
        assert runner.returncode == 0, (runner.stderr, deploy_output(tmp))
        assert process.poll() is None


def test_one_policy_file_sees_the_same_keys_in_the_env_a_sweep_and_rskill_run(
    tmp_path: Path,
) -> None:
    logs = {path: tmp_path / f"{path}.jsonl" for path in ("env", "sweep", "rskill")}
    _env_loop(logs["env"])
    dataset = _sweep(tmp_path / "sweep", logs["sweep"])
    _rskill(tmp_path, logs["rskill"])
    seen = {path: _seen(log) for path, log in logs.items()}
    kinds = {path: lines[-1]["keys"] for path, lines in seen.items()}
    for path, keys in kinds.items():
        assert set(keys) >= SHARED, (path, sorted(keys))  # type: ignore[arg-type]
    assert set(kinds["env"]) == set(kinds["sweep"])  # the sweep's obs is the env's
    for key in set.intersection(*(set(keys) for keys in kinds.values())):  # type: ignore[arg-type]
        assert len({json.dumps(keys[key]) for keys in kinds.values()}) == 1, key  # type: ignore[index]
    rows = pq.read_table(dataset / "data" / "chunk-000" / "file-000.parquet").to_pydict()
    for key in ("observation.state", "observation.velocity", "observation.tcp_pose"):
        saw = np.array([line[key] for line in seen["sweep"]], dtype=np.float32)
        np.testing.assert_array_equal(np.array(rows[key], dtype=np.float32), saw, err_msg=key)
