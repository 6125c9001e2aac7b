"""Episodes written as a LeRobot v3.0 dataset read back as written, pass lerobot-doctor
(no errors), their videos decode to the frames written and their statistics match numpy's.
The three synthetic episodes (:mod:`tests.eval.lerobot_samples`) are written once per module.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from openral_eval import lerobot_stats
from openral_eval.lerobot_dataset import (
    DatasetSummary,
    write_dataset,
)

from tests.eval.lerobot_samples import (
    DATA_COLUMNS,
    EPISODES,
    FPS,
    HEIGHT,
    LAYOUT,
    QUANTILES,
    SPECS,
    WIDTH,
    _decode,
    _episode_rows,
    _info,
    _video,
    doctor,
)


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, DatasetSummary]:
    folder = tmp_path_factory.mktemp("lerobot") / "dataset"
    return folder, write_dataset(folder, LAYOUT, iter(EPISODES))


def test_the_files_of_a_v3_dataset_are_written(written: tuple[Path, DatasetSummary]) -> None:
    folder, summary = written
    assert summary == DatasetSummary(folder=folder, episodes=3, frames=36, tasks=2)
    files = sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())
    assert files == [
        "data/chunk-000/file-000.parquet",
        "meta/episodes/chunk-000/file-000.parquet",
        "meta/info.json",
        "meta/stats.json",
        "meta/tasks.parquet",
        "videos/observation.images.front/chunk-000/file-000.mp4",
        "videos/observation.images.wrist/chunk-000/file-000.mp4",
    ]
    assert [p.name for p in folder.parent.iterdir()] == ["dataset"]  # no staging folder left


def test_info_json_describes_the_dataset(written: tuple[Path, DatasetSummary]) -> None:
    info = _info(written[0])
    features = info.pop("features")
    assert info == {
        "codebase_version": "v3.0",
        "robot_type": "franka_panda",
        "total_episodes": 3,
        "total_frames": 36,
        "total_tasks": 2,
        "chunks_size": 1000,
        "data_files_size_in_mb": 100,
        "video_files_size_in_mb": 200,
        "fps": 10,
        "splits": {"train": "0:3"},
        "data_path": "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet",
        "video_path": "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4",
    }
    assert isinstance(features, dict)
    assert features["observation.state"] == {
        "dtype": "float32",
        "shape": [9],
        "names": list(LAYOUT.state_names),
    }
    assert features["action"] == {
        "dtype": "float32",
        "shape": [8],
        "names": list(LAYOUT.action_names),
    }
    assert features["next.success"] == {"dtype": "bool", "shape": [1], "names": None}
    for name, dtype in [("timestamp", "float32")] + [
        (n, "int64") for n in ("frame_index", "episode_index", "index", "task_index")
    ]:
        assert features[name] == {"dtype": dtype, "shape": [1], "names": None}
    for slot in LAYOUT.cameras:
        camera = features[f"observation.images.{slot}"]
        assert camera["dtype"] == "video"
        assert camera["shape"] == [HEIGHT, WIDTH, 3]
        assert camera["names"] == ["height", "width", "channels"]
        video = camera["info"]
        assert video["video.codec"] in ("h264", "mpeg4")
        assert (video["video.height"], video["video.width"], video["video.fps"]) == (48, 64, 10)
        assert (video["video.pix_fmt"], video["video.channels"]) == ("yuv420p", 3)
        assert video["has_audio"] is False and video["video.is_depth_map"] is False
    assert len(features) == 10


def test_lerobot_doctor_finds_no_error(written: tuple[Path, DatasetSummary]) -> None:
    report, failures = doctor(written[0])
    assert (report["codebase_version"], report["format_version"]) == ("v3.0", "v3")
    assert (report["total_episodes"], report["total_frames"], report["fps"]) == (3, 36, 10)
    assert report["overall_severity"] != "FAIL"
    assert failures == []
    severity = {check["name"]: check["severity"] for check in report["checks"]}
    for name in ("Metadata & Format Compliance", "Temporal Consistency", "Video Integrity"):
        assert severity[name] == "PASS", report
    assert severity["Data Distribution"] == "PASS"  # stats.json covers every data column


def test_the_frames_read_back_as_written(written: tuple[Path, DatasetSummary]) -> None:
    table = pq.read_table(written[0] / "data/chunk-000/file-000.parquet")
    assert tuple(table.column_names) == DATA_COLUMNS
    assert table.schema.field("observation.state").type == pa.list_(pa.float32(), 9)
    assert table.schema.field("action").type == pa.list_(pa.float32(), 8)
    states = np.array(table.column("observation.state").to_pylist(), dtype=np.float32)
    actions = np.array(table.column("action").to_pylist(), dtype=np.float32)
    np.testing.assert_array_equal(states, np.concatenate([e.states for e in EPISODES]))
    np.testing.assert_array_equal(actions, np.concatenate([e.actions for e in EPISODES]))
    success = table.column("next.success").to_numpy(zero_copy_only=False)
    np.testing.assert_array_equal(success, np.concatenate([e.success for e in EPISODES]))
    frame_index = table.column("frame_index").to_numpy()
    steps = np.concatenate([np.arange(length) for length, _ in SPECS])
    np.testing.assert_array_equal(frame_index, steps)
    episode_of = np.repeat([0, 1, 2], [length for length, _ in SPECS])
    np.testing.assert_array_equal(table.column("episode_index").to_numpy(), episode_of)
    np.testing.assert_array_equal(table.column("index").to_numpy(), np.arange(36))
    np.testing.assert_array_equal(
        table.column("task_index").to_numpy(), np.array([0, 1, 0])[episode_of]
    )
    timestamps = table.column("timestamp").to_numpy()
    assert timestamps.dtype == np.float32
    np.testing.assert_array_equal(timestamps, (steps / FPS).astype(np.float32))


def test_episode_rows_locate_each_episode(written: tuple[Path, DatasetSummary]) -> None:
    rows = _episode_rows(written[0])
    starts = [0, 12, 21]
    for index, (row, (length, task)) in enumerate(zip(rows, SPECS, strict=True)):
        assert row["episode_index"] == index and row["tasks"] == [task]
        assert row["length"] == length
        assert (row["dataset_from_index"], row["dataset_to_index"]) == (
            starts[index],
            starts[index] + length,
        )
        assert (row["data/chunk_index"], row["data/file_index"]) == (0, 0)
        assert (row["meta/episodes/chunk_index"], row["meta/episodes/file_index"]) == (0, 0)
        for slot in LAYOUT.cameras:
            key = f"videos/observation.images.{slot}"
            assert (row[f"{key}/chunk_index"], row[f"{key}/file_index"]) == (0, 0)
            assert row[f"{key}/from_timestamp"] == pytest.approx(starts[index] / FPS)
            assert row[f"{key}/to_timestamp"] == pytest.approx((starts[index] + length) / FPS)


def _numpy_stats(values: npt.NDArray[np.float64]) -> dict[str, npt.NDArray[np.float64]]:
    """numpy's statistics over axis 0 of (N, k) values."""
    stats = {
        "min": values.min(axis=0),
        "max": values.max(axis=0),
        "mean": values.mean(axis=0),
        "std": values.std(axis=0),
    }
    return stats | {key: np.quantile(values, q, axis=0) for key, q in QUANTILES.items()}


def _pixels(frames: npt.NDArray[np.uint8]) -> npt.NDArray[np.float64]:
    return frames.reshape(-1, 3).astype(np.float64) / 255.0


def test_episode_stats_match_numpy(written: tuple[Path, DatasetSummary]) -> None:
    for row, episode in zip(_episode_rows(written[0]), EPISODES, strict=True):
        length = len(episode.states)
        for feature, values in (
            ("observation.state", episode.states.astype(np.float64)),
            ("action", episode.actions.astype(np.float64)),
            ("next.success", episode.success.astype(np.float64)[:, None]),
            ("frame_index", np.arange(length, dtype=np.float64)[:, None]),
        ):
            for name, expected in _numpy_stats(values).items():
                got = np.array(row[f"stats/{feature}/{name}"])
                np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12, err_msg=name)
            assert row[f"stats/{feature}/count"] == [length]
        for slot in LAYOUT.cameras:
            feature = f"stats/observation.images.{slot}"
            for name, expected in _numpy_stats(_pixels(episode.frames[slot])).items():
                got = np.array(row[f"{feature}/{name}"])
                assert got.shape == (3, 1, 1)
                np.testing.assert_allclose(got.ravel(), expected, rtol=1e-9, err_msg=name)
            assert row[f"{feature}/count"] == [length]  # every frame is sampled below 100


def test_stats_json_matches_numpy_over_the_dataset(written: tuple[Path, DatasetSummary]) -> None:
    stats = json.loads((written[0] / "meta" / "stats.json").read_text())
    assert set(stats) == {*DATA_COLUMNS, "observation.images.front", "observation.images.wrist"}
    for feature, values in (
        ("observation.state", [e.states.astype(np.float64) for e in EPISODES]),
        ("action", [e.actions.astype(np.float64) for e in EPISODES]),
        ("observation.images.front", [_pixels(e.frames["front"]) for e in EPISODES]),
        ("observation.images.wrist", [_pixels(e.frames["wrist"]) for e in EPISODES]),
    ):
        shape = (3, 1, 1) if "images" in feature else (values[0].shape[1],)
        overall = _numpy_stats(np.concatenate(values))
        per_episode = [_numpy_stats(v) for v in values]
        for name in ("min", "max", "mean", "std"):
            got = np.array(stats[feature][name])
            assert got.shape == shape
            np.testing.assert_allclose(got.ravel(), overall[name], rtol=1e-9, err_msg=name)
        for name, q in QUANTILES.items():  # LeRobot's envelope of the episodes' quantiles
            pick = np.min if q <= 0.5 else np.max
            expected = pick([s[name] for s in per_episode], axis=0)
            np.testing.assert_allclose(np.ravel(stats[feature][name]), expected, rtol=1e-9)
        assert stats[feature]["count"] == [36]
    assert stats["index"]["max"] == [35.0] and stats["index"]["mean"] == [17.5]
    assert stats["next.success"]["mean"] == [pytest.approx(6 / 36)]
    pixels = np.array(stats["observation.images.front"]["max"]).ravel()
    assert pixels.min() >= 0.0 and pixels.max() <= 1.0


@pytest.mark.parametrize("seed", range(12))
def test_image_stats_match_numpy_on_tied_pixels(seed: int) -> None:
    """Few grey levels, so quantiles fall on ties and between levels alike."""
    rng = np.random.default_rng(seed)
    frames = (rng.integers(0, 4, (int(rng.integers(1, 6)), 2, 2, 3)) * 60).astype(np.uint8)
    stats = lerobot_stats.image_stats(frames)
    for name, expected in _numpy_stats(_pixels(frames)).items():
        np.testing.assert_allclose(stats[name].ravel(), expected, rtol=1e-12, err_msg=name)
    assert stats["count"].tolist() == [len(frames)]


def test_image_stats_sample_long_episodes_and_stride_big_frames_as_lerobot() -> None:
    frames = np.random.default_rng(0).integers(0, 256, (1000, 4, 450, 3), dtype=np.uint8)
    stats = lerobot_stats.image_stats(frames)
    sample = np.round(np.linspace(0, 999, 177)).astype(int)  # 1000 ** 0.75 frames
    expected = _numpy_stats(_pixels(frames[sample][:, ::3, ::3]))  # 450 px -> every 3rd
    for name in ("min", "max", "mean", "std"):
        np.testing.assert_allclose(stats[name].ravel(), expected[name], rtol=1e-9)
    assert stats["count"].tolist() == [177]


def test_tasks_parquet_indexes_tasks_by_text(written: tuple[Path, DatasetSummary]) -> None:
    table = pq.read_table(written[0] / "meta" / "tasks.parquet")
    assert table.to_pylist() == [
        {"task_index": 0, "task": "lift the red cube"},
        {"task_index": 1, "task": "push the block"},
    ]
    note = json.loads(table.schema.metadata[b"pandas"])
    assert note["index_columns"] == ["task"]


@pytest.mark.parametrize("slot", LAYOUT.cameras)
def test_each_video_decodes_to_the_written_frames(
    written: tuple[Path, DatasetSummary], slot: str
) -> None:
    pictures, times = _decode(_video(written[0], slot))
    assert pictures.shape == (36, HEIGHT, WIDTH, 3)
    written_frames = np.concatenate([e.frames[slot] for e in EPISODES]).astype(np.int16)
    errors = np.abs(pictures.astype(np.int16) - written_frames).mean(axis=(1, 2, 3))
    assert errors.max() < 6.0, errors  # lossy, but close
    shifted = np.abs(pictures[1:].astype(np.int16) - written_frames[:-1]).mean(axis=(1, 2, 3))
    assert shifted.min() > 3 * errors.max()  # a frame off by one would not pass
    if times is not None:  # each episode's frames at from_timestamp + frame_index / fps
        for row in _episode_rows(written[0]):
            start, end = row["dataset_from_index"], row["dataset_to_index"]
            assert isinstance(start, int) and isinstance(end, int)
            origin = row[f"videos/observation.images.{slot}/from_timestamp"]
            assert isinstance(origin, float)
            expected = origin + np.arange(end - start) / FPS
            np.testing.assert_allclose(times[start:end], expected, atol=1e-4)
