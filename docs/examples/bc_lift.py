"""Teach a small network to lift the cube of the Panda tabletop: behaviour cloning, then DAgger.

    python docs/examples/bc_lift.py OUT [--demos N] [--rounds R] [--per-round N] [--epochs E]

1. A scripted teacher (:class:`Teacher`) lifts the cube on ``--demos`` seeds; ``openral sim
   sweep --dataset`` keeps what it saw and did as a LeRobot dataset.
2. A two-layer MLP (numpy, Adam) learns the teacher's action from what it saw: the TCP, the
   cube's pose, the gripper (:func:`features`).
3. Each of ``--rounds`` DAgger rounds sweeps ``--per-round`` new seeds with the network
   driving (:class:`Dagger`) while the teacher says what it would have done in each state
   the network reached; the network is trained again on everything taught so far.

Each round's sweep also measures the network that drove it; the one that lifted the cube
most often (a tie: the later) is kept as ``OUT/lift.npz``. Sweep it as ``--policy
docs/examples/bc_lift.py:ClonedLift -p weights=OUT/lift.npz``. Every step of the way is an
ordinary ``openral sim sweep``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import time
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pyarrow.parquet as pq

SCENE = "robots/franka_panda/scenes/tabletop.yaml"
CUBE = "red_cube"
HIDDEN = 256
LEARNED = [0, 1, 2, 5, 6]
"""The action values the network learns: dx, dy, dz, the yaw rate rz and the gripper; rx
and ry stay 0, as the teacher's do (the hand keeps pointing down)."""
LIFT_Z = 0.15
"""Where the teacher lifts the cube to, in the robot's base frame [m] (5 cm up is success)."""
Array = npt.NDArray[np.float64]


def yaw(quat: npt.ArrayLike) -> Array:
    """Yaw [rad] of the x axis of frames with quaternions (w, x, y, z) ``quat``."""
    w, x, y, z = np.moveaxis(np.asarray(quat, np.float64), -1, 0)
    return np.asarray(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


def turn_to_face(cube_quat: npt.ArrayLike, tcp_quat: npt.ArrayLike) -> Array:
    """The turn [rad] from the hand to the cube's nearest face (a cube looks the same every
    90 degrees), in [-45, 45) degrees."""
    turn = yaw(cube_quat) - yaw(tcp_quat)
    return np.asarray((turn + np.pi / 4) % (np.pi / 2) - np.pi / 4)


def features(tcp: Array, cube_pos: Array, cube_quat: Array, state: Array, speed: Array) -> Array:
    """The network's input: the TCP's position (base frame), the cube's (world frame), the
    cube seen from the TCP, the turn to its nearest face, the gripper's opening (the last
    joint of ``observation.state``) and speed (of ``observation.velocity``, /10)."""
    turn = turn_to_face(cube_quat, tcp[..., 3:])
    parts = [tcp[..., :3], cube_pos, cube_pos - tcp[..., :3], turn[..., None]]
    parts += [state[..., -1:], speed[..., -1:] / 10.0]
    return np.concatenate(parts, axis=-1)


def seen(obs: dict[str, object]) -> Array:
    """:func:`features` of one observation (the one every openral path gives a policy)."""
    task = obs["task_state"]
    assert isinstance(task, dict)
    vector = {k: np.asarray(obs[k], np.float64) for k in ("observation.tcp_pose",
              "observation.state", "observation.velocity")}  # fmt: skip
    return features(
        vector["observation.tcp_pose"], np.asarray(task[f"{CUBE}_pos"], np.float64),
        np.asarray(task[f"{CUBE}_quat"], np.float64), vector["observation.state"],
        vector["observation.velocity"],
    )  # fmt: skip


class Teacher:
    """A scripted lift that decides from what it sees now (it keeps no phase between steps,
    so it can say what to do in any state a learner reaches): above the cube, down to it,
    close, lift. End-effector deltas in robosuite's convention (-1 opens the gripper)."""

    required_slots = ()
    needs_privileged = True  # the cube's pose and the robot's base
    action_mode = "ee_delta_pose"

    def act(self, obs: dict[str, object]) -> Array:
        tcp = np.asarray(obs["observation.tcp_pose"], np.float64)
        world, task = obs["privileged"], obs["task_state"]
        assert isinstance(task, dict)
        cube = np.asarray(task[f"{CUBE}_pos"], np.float64) - world.base[0]  # type: ignore[attr-defined]
        finger = float(np.asarray(obs["observation.state"])[-1])
        closing = abs(float(np.asarray(obs["observation.velocity"])[-1])) > 0.05
        error = cube - tcp[:3]
        action = np.zeros(7)
        if finger > 0.95 and np.linalg.norm(error) < 0.008:
            action[6] = 1.0  # at the cube and open: close
        elif finger <= 0.95 and (closing or np.linalg.norm(error) < 0.03):
            action[6] = 1.0  # closing, or holding it: lift once the fingers have stopped
            if not closing:
                action[:3] = _towards(np.array([cube[0], cube[1], LIFT_Z]) - tcp[:3], 0.15)
        else:
            action[6] = -1.0  # open, above the cube, then down to it
            aligned = np.linalg.norm(error[:2]) < 0.008 and tcp[2] > cube[2] - 0.002
            target = cube if aligned else cube + np.array([0.0, 0.0, 0.10])
            action[:3] = _towards(target - tcp[:3], 0.35)
        turn = float(turn_to_face(task[f"{CUBE}_quat"], tcp[3:]))
        action[5] = np.clip(6.0 * turn, -1.5, 1.5) * 0.05 / 0.5  # 0.5 rad full scale a step
        return np.clip(action, -1.0, 1.0)


def _towards(error: Array, top_m_s: float) -> Array:
    """Six times the position error [m/s], at most ``top_m_s``, as a step of the preset
    (0.05 m full scale a 0.05 s step: the same numbers)."""
    velocity = 6.0 * error
    speed = float(np.linalg.norm(velocity))
    return velocity * (top_m_s / speed if speed > top_m_s else 1.0)


@dataclass(frozen=True)
class ClonedConfig:
    weights: str = "lift.npz"


class ClonedLift:
    """The trained network as a policy (its weights read when it is built, in the worker
    that runs the episode)."""

    config_type = ClonedConfig
    required_slots = ()
    needs_privileged = True  # it reads the cube's pose
    action_mode = "ee_delta_pose"

    def __init__(self, config: ClonedConfig) -> None:
        with np.load(config.weights) as saved:
            self.params = [saved[f"p{k}"] for k in range(6)]
            self.mean, self.std = saved["mean"], saved["std"]

    def act(self, obs: dict[str, object]) -> Array:
        action = np.zeros(7)
        action[LEARNED] = np.clip(predict(self.params, self.mean, self.std, seen(obs)), -1, 1)
        action[6] = 1.0 if action[6] > 0 else -1.0  # the gripper: close or open
        return action


@dataclass(frozen=True)
class DaggerConfig:
    weights: str = "lift.npz"
    labels: str = "labels"
    teacher_share: float = 0.0
    """Share of the steps the teacher's own action is taken (DAgger's beta)."""


class Dagger(ClonedLift):
    """The network drives (the teacher instead, on ``teacher_share`` of the steps); the
    teacher, shown the same observation, says what it would do, and each (input, teacher's
    action) is appended to a file of its own in ``labels``."""

    config_type = DaggerConfig  # type: ignore[assignment]

    def __init__(self, config: DaggerConfig) -> None:
        super().__init__(ClonedConfig(config.weights))
        self.teacher = Teacher()
        Path(config.labels).mkdir(parents=True, exist_ok=True)
        self.file = Path(config.labels) / f"{os.getpid()}-{id(self)}.f64"
        self.share = config.teacher_share
        self.draw: np.random.Generator | None = None

    def act(self, obs: dict[str, object]) -> Array:
        if self.draw is None:  # drawn from the episode's first view: the same every run
            self.draw = np.random.default_rng(np.round(seen(obs) * 1e6).astype(np.int64) % 2**31)
        teacher = self.teacher.act(obs)
        with self.file.open("ab") as out:
            out.write(np.concatenate([seen(obs), teacher[LEARNED]]).tobytes())
        return teacher if self.draw.random() < self.share else super().act(obs)


def demonstrations(dataset: Path) -> tuple[Array, Array]:
    """(inputs, actions) of every frame of a sweep's LeRobot dataset."""
    info = json.loads((dataset / "meta" / "info.json").read_text())["features"]
    rows = pq.read_table(dataset / "data" / "chunk-000" / "file-000.parquet").to_pydict()
    wanted = ("tcp_pose", "state", "velocity", "environment_state")
    column = {f"observation.{k}": np.array(rows[f"observation.{k}"], np.float64) for k in wanted}
    names = info["observation.environment_state"]["names"]

    def entry(name: str, size: int) -> Array:
        picked = [names.index(f"{CUBE}_{name}.{i}") for i in range(size)]
        return column["observation.environment_state"][:, picked]

    x = features(column["observation.tcp_pose"], entry("pos", 3), entry("quat", 4),
                 column["observation.state"], column["observation.velocity"])  # fmt: skip
    return x, np.array(rows["action"], np.float64)[:, LEARNED]


def taught(folder: Path, width: int) -> tuple[Array, Array]:
    """(inputs, teacher's actions) of every DAgger step kept in ``folder``."""
    tables = [np.fromfile(f).reshape(-1, width + len(LEARNED)) for f in folder.glob("*.f64")]
    table = np.concatenate(tables) if tables else np.zeros((0, width + len(LEARNED)))
    table = table[np.lexsort(table.T[::-1])]  # one order whatever the files' names
    return table[:, :width], table[:, width:]


def train(x: Array, y: Array, epochs: int, seed: int = 0) -> dict[str, Array]:
    """A two-layer ReLU MLP fitted by Adam (learning rate 1e-3, batches of 256) to the mean
    squared error; its weights and the input's normalisation."""
    rng = np.random.default_rng(seed)
    mean, std = x.mean(0), x.std(0) + 1e-6
    xs = (x - mean) / std
    sizes = [x.shape[1], HIDDEN, HIDDEN, y.shape[1]]
    params = [rng.normal(0, np.sqrt(2 / a), (a, b)) for a, b in pairwise(sizes)]
    params += [np.zeros(n) for n in sizes[1:]]
    moments = [(np.zeros_like(p), np.zeros_like(p)) for p in params]
    step = 0
    for _ in range(epochs):
        order = rng.permutation(len(xs))
        for start in range(0, len(xs), 256):
            step += 1
            grads = _gradients(
                params, xs[order[start : start + 256]], y[order[start : start + 256]]
            )
            for k, grad in enumerate(grads):
                m, v = moments[k]
                m[:] = 0.9 * m + 0.1 * grad
                v[:] = 0.999 * v + 0.001 * grad**2
                m_hat, v_hat = m / (1 - 0.9**step), v / (1 - 0.999**step)
                params[k] -= 1e-3 * m_hat / (np.sqrt(v_hat) + 1e-8)
    return {"mean": mean, "std": std, **{f"p{k}": p for k, p in enumerate(params)}}


def _gradients(params: list[Array], x: Array, y: Array) -> list[Array]:
    w0, w1, w2, b0, b1, b2 = params
    h1 = np.maximum(x @ w0 + b0, 0)
    h2 = np.maximum(h1 @ w1 + b1, 0)
    g = 2 * (h2 @ w2 + b2 - y) / len(x)
    g2 = (g @ w2.T) * (h2 > 0)
    g1 = (g2 @ w1.T) * (h1 > 0)
    return [x.T @ g1, h1.T @ g2, h2.T @ g, g1.sum(0), g2.sum(0), g.sum(0)]


def predict(params: list[Array], mean: Array, std: Array, x: Array) -> Array:
    w0, w1, w2, b0, b1, b2 = params
    h = np.maximum(((x - mean) / std) @ w0 + b0, 0)
    return np.asarray(np.maximum(h @ w1 + b1, 0) @ w2 + b2)


def sweep(out: Path, seeds: str, policy: str, *extra: str) -> int:
    """``openral sim sweep`` of the scene (no video); how many episodes succeeded."""
    command = ["openral", "sim", "sweep", "--config", SCENE, "--seeds", seeds, "--video", "none"]
    command += ["--policy", f"{__file__}:{policy}", "--out", str(out), *extra]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    lines = (out / "episodes.jsonl").read_text().splitlines()
    return sum(json.loads(line)["success"] for line in lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--demos", type=int, default=200)
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--per-round", type=int, default=200)
    parser.add_argument("--epochs", type=int, default=30)
    args = parser.parse_args()
    began = time.perf_counter()
    lifted = sweep(args.out / "teacher", f"0:{args.demos}", "Teacher", "--dataset",
                   str(args.out / "teacher" / "ds"))  # fmt: skip
    x, y = demonstrations(args.out / "teacher" / "ds")
    print(f"teacher: lifted {lifted}/{args.demos}, {len(x)} steps shown")
    driving = args.out / "lift-0.npz"
    np.savez(driving, **train(x, y, args.epochs))
    best: tuple[int, int, Path] = (-1, 0, driving)
    for k in range(1, args.rounds + 1):
        labels = args.out / f"labels-{k}"
        first = 10_000 + k * args.per_round  # seeds of its own, apart from the demos'
        seeds = f"{first}:{first + args.per_round}"
        lifted = sweep(args.out / f"round-{k}", seeds, "Dagger", "--steps", "150",
                       "-p", f"weights={driving}", "-p", f"labels={labels}",
                       "-p", f"teacher_share={0.5**k}")  # fmt: skip
        best = max(best, (lifted, k, driving))  # a tie: the later round's network
        more_x, more_y = taught(labels, x.shape[1])
        x, y = np.concatenate([x, more_x]), np.concatenate([y, more_y])
        driving = args.out / f"lift-{k}.npz"
        np.savez(driving, **train(x, y, args.epochs))
        print(f"round {k}: the network lifted {lifted}/{args.per_round}; trained on {len(x)} steps")
    weights = args.out / "lift.npz"
    shutil.copyfile(best[2], weights)
    print(f"kept the network that drove round {best[1]} ({best[0]}/{args.per_round} lifted)")
    print(f"wrote {weights} in {time.perf_counter() - began:.0f} s")


if __name__ == "__main__":
    main()
