"""``openral sim sweep --dataset``: a sweep's episodes as a LeRobot v3.0 dataset, run as a
user runs it. The dataset passes lerobot-doctor with no failure, holds one episode per seed
with as many frames as the episode took steps, its actions are the env's (ee_delta_pose for
scripted_lift), its videos decode; a folder that exists, or holds another robot's
episodes, is refused in one line."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import av
import numpy as np
import pyarrow.parquet as pq
import pytest

from tests.conftest import REPO
from tests.eval.lerobot_samples import doctor

OPENRAL = Path(sys.executable).parent / "openral"
SCENE = REPO / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
SEEDS = 3


def _openral(*args: str) -> subprocess.CompletedProcess[str]:
    """``openral ARGS`` as a user runs it (wide output, offscreen rendering)."""
    env = {**os.environ, "MUJOCO_GL": "egl", "COLUMNS": "200"}
    return subprocess.run(
        [str(OPENRAL), *args], capture_output=True, text=True, timeout=600, env=env
    )


def _sweep(out: Path, dataset: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    command = [str(OPENRAL), "sim", "sweep", "--config", str(SCENE), "--seeds", f"0:{SEEDS}"]
    command += ["--policy", "scripted_lift", "--video", "none", "--out", str(out)]
    return subprocess.run(
        [*command, "--dataset", str(dataset), *extra],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "MUJOCO_GL": "egl"},
    )


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("sweep_dataset")
    done = _sweep(root / "o", root / "o" / "ds")
    assert done.returncode == 0, done.stderr
    assert f"wrote {root / 'o' / 'ds'} (LeRobot v3.0: {SEEDS} episodes" in done.stdout
    return root / "o", root / "o" / "ds"


def test_the_dataset_passes_lerobot_doctor(swept: tuple[Path, Path]) -> None:
    report, failures = doctor(swept[1])
    assert (report["total_episodes"], report["fps"]) == (SEEDS, 20)
    assert failures == [] and report["overall_severity"] != "FAIL"


def test_one_episode_per_seed_with_a_frame_per_step(swept: tuple[Path, Path]) -> None:
    out, dataset = swept
    results = [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]
    info = json.loads((dataset / "meta" / "info.json").read_text())
    assert info["robot_type"] == "franka_panda" and info["fps"] == 20
    assert info["total_episodes"] == SEEDS
    assert info["total_frames"] == sum(r["steps"] for r in results)
    names = info["features"]["action"]["names"]
    assert names == ["dx", "dy", "dz", "rx", "ry", "rz", "gripper"]  # the policy's mode
    assert set(info["features"]) >= {"observation.images.camera1", "observation.images.camera2"}
    data = pq.read_table(dataset / "data" / "chunk-000" / "file-000.parquet").to_pydict()
    episodes = np.array(data["episode_index"])
    for index, result in enumerate(results):
        assert (episodes == index).sum() == result["steps"]
        last = int(np.flatnonzero(episodes == index)[-1])
        assert bool(data["next.success"][last]) == result["success"]
    actions = np.array(data["action"])
    assert np.all(np.abs(actions) <= 1.0) and np.abs(actions).max() > 0.1
    tasks = pq.read_table(dataset / "meta" / "tasks.parquet").to_pylist()
    assert [t["task"] for t in tasks] == ["lift the red cube"]
    assert not (out / "dataset-episodes").exists()  # the staging is gone


def test_each_camera_video_decodes_to_a_frame_per_step(swept: tuple[Path, Path]) -> None:
    _, dataset = swept
    info = json.loads((dataset / "meta" / "info.json").read_text())
    for key in ("observation.images.camera1", "observation.images.camera2"):
        video = dataset / "videos" / key / "chunk-000" / "file-000.mp4"
        with av.open(str(video)) as container:
            frames = [f.to_ndarray(format="rgb24") for f in container.decode(video=0)]
        assert len(frames) == info["total_frames"]
        assert frames[0].shape == (128, 128, 3) and frames[0].std() > 5.0


def test_an_existing_or_foreign_dataset_folder_is_refused(
    swept: tuple[Path, Path], tmp_path: Path
) -> None:
    _, dataset = swept
    done = _sweep(tmp_path / "o2", dataset)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [
        f"error: {dataset} exists; add --resume to finish that sweep and rebuild it, or "
        "choose another --dataset"
    ]
    info = json.loads((dataset / "meta" / "info.json").read_text())
    foreign = tmp_path / "so101_ds"
    (foreign / "meta").mkdir(parents=True)
    (foreign / "meta" / "info.json").write_text(json.dumps({**info, "robot_type": "so101"}))
    done = _sweep(tmp_path / "o3", foreign, "--resume")
    assert done.returncode == 1
    assert "holds so101 episodes; this sweep's robot is franka_panda" in done.stderr
    assert not (tmp_path / "o3" / "episodes.jsonl").exists()  # refused before any episode


@pytest.mark.parametrize("source", ["dataset", "results"])
def test_replaying_an_episode_gives_the_sweeps_trajectory_and_its_video(
    swept: tuple[Path, Path], tmp_path: Path, source: str
) -> None:
    """From the dataset (its actions) or from the sweep's results folder (the policy again)."""
    out, dataset = swept
    results = [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]
    video = tmp_path / "ep2.mp4"
    folder = dataset if source == "dataset" else out
    done = _openral("sim", "replay", str(folder), "--episode", "2", "--video", str(video))
    assert done.returncode == 0, done.stderr
    steps = results[2]["steps"]
    assert f"episode 2 ({SCENE}, seed 2): {steps} steps replayed; the trajectory matches" in (
        done.stdout
    )
    assert results[2]["trajectory_sha256"][:12] in done.stdout
    with av.open(str(video)) as container:
        frames = [f.to_ndarray(format="rgb24") for f in container.decode(video=0)]
    counted = f" ({len(frames)} frames)" if source == "dataset" else ""
    assert f"video: {video}{counted}\n" in done.stdout
    assert 0 < len(frames) <= steps + 1
    assert all(frame.std() > 10 for frame in frames)  # pictures, not a blank stream


def test_a_folder_that_is_neither_is_one_line(tmp_path: Path) -> None:
    nowhere = _openral("sim", "replay", str(tmp_path), "--episode", "0")
    assert nowhere.returncode == 1
    assert "(or a sweep's folder with its episodes.jsonl)" in nowhere.stderr


def test_a_changed_action_no_longer_replays_the_sweep(
    swept: tuple[Path, Path], tmp_path: Path
) -> None:
    import shutil

    import pyarrow as pa

    copy = tmp_path / "ds"
    shutil.copytree(swept[1], copy)
    path = copy / "data" / "chunk-000" / "file-000.parquet"
    table = pq.read_table(path)
    actions = table.column("action").to_pylist()
    first = table.column("episode_index").to_pylist().index(1)
    actions[first + 5][0] += 0.5  # episode 1, step 5, dx
    column = pa.array(actions, type=table.schema.field("action").type)
    pq.write_table(table.set_column(table.schema.get_field_index("action"), "action", column), path)
    done = subprocess.run(
        [str(OPENRAL), "sim", "replay", str(copy), "--episode", "1"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MUJOCO_GL": "egl"},
    )
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "the trajectory differs from the sweep's" in lines[0], done.stderr
    done = subprocess.run(
        [str(OPENRAL), "sim", "replay", str(copy), "--episode", "9"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 1 and "holds episodes 0 to 2" in done.stderr


def test_stored_actions_are_float32_inside_their_bounds() -> None:
    from hypothesis import given
    from hypothesis import strategies as st
    from openral_eval.episode_frames import as_stored

    low, high = np.array([-3.0718, -0.0698, -1.0]), np.array([-0.0698, 2.5, 1.0])

    @given(st.lists(st.floats(0.0, 1.0), min_size=3, max_size=3), st.sampled_from([0, 1]))
    def check(shares: list[float], edge: int) -> None:
        action = low + np.array(shares) * (high - low)
        action[0] = (low, high)[edge][0]  # a value on its bound, as a clamp leaves it
        stored = as_stored(action, low, high)
        assert np.all(stored >= low) and np.all(stored <= high)
        assert np.array_equal(stored.astype(np.float32).astype(np.float64), stored)
        assert np.all(np.abs(stored - action) <= 1e-6 * np.maximum(1.0, np.abs(action)))

    check()


def test_a_joint_mode_dataset_clamped_at_a_limit_replays(tmp_path: Path) -> None:
    """``wave`` commands joint 4 at its upper limit (-0.0698 rad, clamped), which float32
    rounds past the limit: the sweep stores a value inside it, and the replay matches."""
    command = [str(OPENRAL), "sim", "sweep", "--config", str(SCENE), "--seeds", "0"]
    command += ["--policy", "wave", "--steps", "15", "--video", "none", "--out", str(tmp_path)]
    env = {**os.environ, "MUJOCO_GL": "egl"}
    dataset = tmp_path / "ds"
    done = subprocess.run(
        [*command, "--dataset", str(dataset)], capture_output=True, text=True, env=env, timeout=300
    )
    assert done.returncode == 0, done.stdout + done.stderr
    result = json.loads((tmp_path / "episodes.jsonl").read_text())
    assert result["error"] is None and result["steps"] == 15
    done = subprocess.run(
        [str(OPENRAL), "sim", "replay", str(dataset), "--episode", "0"],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert done.returncode == 0 and "the trajectory matches" in done.stdout, done.stderr


def _export(results: Path, dataset: Path) -> subprocess.CompletedProcess[str]:
    return _openral("sim", "export", str(results), str(dataset))


def test_exporting_the_sweeps_results_writes_the_dataset_it_wrote(
    swept: tuple[Path, Path], tmp_path: Path
) -> None:
    out, dataset = swept
    done = _export(out, tmp_path / "again")
    assert done.returncode == 0, done.stderr
    assert f"{SEEDS} episodes rerun, each as the sweep ran it" in done.stdout
    data = Path("data") / "chunk-000" / "file-000.parquet"
    assert pq.read_table(tmp_path / "again" / data).equals(pq.read_table(dataset / data))
    for meta in ("info.json", "openral.json"):
        mine = json.loads((tmp_path / "again" / "meta" / meta).read_text())
        assert mine == json.loads((dataset / "meta" / meta).read_text()), meta
    assert not (out / ".export").exists()


def test_an_export_that_does_not_rerun_as_recorded_writes_nothing(
    swept: tuple[Path, Path], tmp_path: Path
) -> None:
    results = tmp_path / "o"
    results.mkdir()
    lines = (swept[0] / "episodes.jsonl").read_text().splitlines()
    tampered = json.loads(lines[1]) | {"trajectory_sha256": "0" * 64}
    lines[1] = json.dumps(tampered)
    (results / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    done = _export(results, tmp_path / "ds")
    assert done.returncode == 1
    assert "seed 1 did not rerun as the sweep ran it (its trajectory differs" in done.stderr
    assert not (tmp_path / "ds").exists() and not (results / ".export").exists()
    missing = _export(tmp_path / "nowhere", tmp_path / "ds")
    assert missing.returncode == 1
    assert "nowhere/episodes.jsonl: No such file or directory; expected a sweep's results" in (
        missing.stderr
    )
    (results / "episodes.jsonl").write_text('{"seed": 1}\n')
    broken = _export(results, tmp_path / "ds")
    assert broken.returncode == 1 and "episodes.jsonl:1: not a sweep's result line" in broken.stderr
