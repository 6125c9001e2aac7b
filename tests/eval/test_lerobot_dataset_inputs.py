"""Writing a LeRobot dataset: an empty folder is written into, a dataset without cameras has no
videos, episodes stream one at a time, MPEG-4 stands in without libx264, and each bad input is
refused in one line with nothing left behind."""

from __future__ import annotations

import gc
import json
import os
import weakref
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path

import imageio_ffmpeg
import numpy as np
import numpy.typing as npt
import pyarrow.parquet as pq
import pytest
from openral_core.errors import OpenralError
from openral_eval import lerobot_video
from openral_eval.lerobot_dataset import (
    DatasetEpisode,
    DatasetLayout,
    write_dataset,
)

from tests.eval.lerobot_samples import (
    EPISODES,
    LAYOUT,
    SPECS,
    _decode,
    _episode,
    _info,
    _pictures,
    _video,
)


def test_an_empty_folder_is_written_into(tmp_path: Path) -> None:
    folder = tmp_path / "empty"
    folder.mkdir()
    summary = write_dataset(folder, LAYOUT, EPISODES[1:2])
    assert (summary.episodes, summary.frames, summary.tasks) == (1, 9, 1)
    assert _info(folder)["total_frames"] == 9


def test_a_dataset_without_cameras_has_no_videos(tmp_path: Path) -> None:
    layout = replace(LAYOUT, cameras=(), fps=12.5)
    episode = replace(EPISODES[0], frames={})
    write_dataset(tmp_path / "blind", layout, [episode])
    info = _info(tmp_path / "blind")
    assert info["video_path"] is None and info["fps"] == 12.5
    assert not (tmp_path / "blind" / "videos").exists()
    table = pq.read_table(tmp_path / "blind/data/chunk-000/file-000.parquet")
    expected = (np.arange(12) / 12.5).astype(np.float32)
    np.testing.assert_array_equal(table.column("timestamp").to_numpy(), expected)


def test_episodes_stream_one_at_a_time(tmp_path: Path) -> None:
    """When the next episode is asked for, the writer holds no frame of the previous one."""
    previous: list[weakref.ref[npt.NDArray[np.uint8]]] = []
    alive_when_asked: list[bool] = []

    def stream() -> Iterator[DatasetEpisode]:
        for index in range(len(SPECS)):
            gc.collect()
            alive_when_asked.append(any(ref() is not None for ref in previous))
            episode = _episode(index)
            previous[:] = [weakref.ref(pictures) for pictures in episode.frames.values()]
            yield episode
            del episode

    assert write_dataset(tmp_path / "streamed", LAYOUT, stream()).frames == 36
    assert alive_when_asked == [False, False, False]


def test_the_mpeg4_encoder_stands_in_without_libx264(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real = imageio_ffmpeg.get_ffmpeg_exe()
    fake = tmp_path / "ffmpeg"  # the bundled ffmpeg, minus libx264 in its encoder list
    fake.write_text(
        "#!/bin/sh\n"
        f'case " $* " in *" -encoders "*) "{real}" "$@" | grep -v libx264 ;;\n'
        f'*) exec "{real}" "$@" ;; esac\n'
    )
    fake.chmod(0o755)
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: str(fake))
    lerobot_video.video_codec.cache_clear()
    try:
        write_dataset(tmp_path / "mpeg4", LAYOUT, EPISODES[:2])
    finally:
        lerobot_video.video_codec.cache_clear()
    features = _info(tmp_path / "mpeg4")["features"]
    assert isinstance(features, dict)
    assert features["observation.images.front"]["info"]["video.codec"] == "mpeg4"
    pictures, _ = _decode(_video(tmp_path / "mpeg4", "front"))
    written_frames = np.concatenate([e.frames["front"] for e in EPISODES[:2]])
    assert pictures.shape == written_frames.shape
    assert np.abs(pictures.astype(np.int16) - written_frames).mean() < 6.0


def _with(index: int, **changes: object) -> list[DatasetEpisode]:
    """The three episodes, episode ``index`` changed."""
    episodes = list(EPISODES)
    episodes[index] = replace(episodes[index], **changes)  # type: ignore[arg-type]
    return episodes


def _nan_at(values: npt.NDArray[np.float32], frame: int, entry: int) -> npt.NDArray[np.float32]:
    bad = values.copy()
    bad[frame, entry] = np.nan
    return bad


BAD_INPUTS: dict[str, tuple[Callable[[], tuple[DatasetLayout, list[DatasetEpisode]]], str]] = {
    "no episodes": (lambda: (LAYOUT, []), "no episodes to write; expected at least one"),
    "zero fps": (
        lambda: (replace(LAYOUT, fps=0.0), EPISODES),
        "layout.fps is 0.0; expected a finite rate > 0 [Hz]",
    ),
    "state width": (
        lambda: (LAYOUT, _with(0, states=EPISODES[0].states[:, :8])),
        "episode 0: states has shape (12, 8); expected (12, 9): one row per frame, "
        "one column per layout.state_names entry",
    ),
    "action width": (
        lambda: (LAYOUT, _with(1, actions=EPISODES[1].actions[:, :7])),
        "episode 1: actions has shape (9, 7); expected (9, 8)",
    ),
    "success length": (
        lambda: (LAYOUT, _with(2, success=EPISODES[2].success[:14])),
        "episode 2: success has shape (14,); expected (15,): one row per frame",
    ),
    "float success": (
        lambda: (LAYOUT, _with(1, success=EPISODES[1].success.astype(np.float32))),
        "episode 1: success has dtype float32; expected bool",
    ),
    "nan state": (
        lambda: (LAYOUT, _with(1, states=_nan_at(EPISODES[1].states, 3, 2))),
        "episode 1: states has 1 non-finite value(s) (NaN, inf or beyond float32), "
        "first at frame 3, entry 2; expected finite numbers",
    ),
    "huge action": (
        lambda: (LAYOUT, _with(2, actions=EPISODES[2].actions.astype(np.float64) * 1e300)),
        "episode 2: actions has 120 non-finite value(s)",
    ),
    "missing camera": (
        lambda: (LAYOUT, _with(1, frames={"front": EPISODES[1].frames["front"]})),
        "episode 1: frames has camera slots ['front']; "
        "expected exactly layout.cameras ['front', 'wrist']",
    ),
    "camera size changes": (
        lambda: (LAYOUT, _with(2, frames={**EPISODES[2].frames, "wrist": _pictures(15, 0)[:, 8:]})),
        "episode 2: frames['wrist'] is uint8 (15, 40, 64, 3); "
        "expected (15, 48, 64, 3) uint8 with H and W even",
    ),
    "camera frames short": (
        lambda: (LAYOUT, _with(0, frames={**EPISODES[0].frames, "front": _pictures(11, 0)})),
        "episode 0: frames['front'] is uint8 (11, 48, 64, 3); expected (12, H, W, 3)",
    ),
    "odd height": (
        lambda: (LAYOUT, _with(0, frames={**EPISODES[0].frames, "front": _pictures(12, 0)[:, 1:]})),
        "episode 0: frames['front'] is uint8 (12, 47, 64, 3); expected (12, H, W, 3) uint8 "
        "with H and W even",
    ),
    "empty task": (lambda: (LAYOUT, _with(1, task=" ")), "episode 1: task is ' '; expected"),
    "extra missing": (
        lambda: (replace(LAYOUT, extra={"observation.velocity": ("a", "b")}), EPISODES),
        "episode 0: extra has features []; expected exactly layout.extra ['observation.velocity']",
    ),
    "extra width": (
        lambda: (
            replace(LAYOUT, extra={"observation.velocity": ("a", "b")}),
            [
                replace(e, extra={"observation.velocity": np.zeros((len(e.success), 3))})
                for e in EPISODES
            ],
        ),
        "episode 0: extra['observation.velocity'] is float64 (12, 3); expected real numbers of "
        "shape (12, 2)",
    ),
    "extra images": (
        lambda: (replace(LAYOUT, extra={"observation.images.x": ("a",)}), EPISODES),
        "layout.extra has 'observation.images.x'; expected observation.* keys other than",
    ),
}


def test_extra_features_are_columns_with_names_and_stats(tmp_path: Path) -> None:
    layout = replace(LAYOUT, extra={"observation.velocity": ("a", "b")})
    speeds = [np.arange(2 * len(e.success), dtype=np.float32).reshape(-1, 2) for e in EPISODES]
    episodes = [
        replace(e, extra={"observation.velocity": v}) for e, v in zip(EPISODES, speeds, strict=True)
    ]
    write_dataset(tmp_path / "d", layout, episodes)
    features = _info(tmp_path / "d")["features"]
    assert isinstance(features, dict)
    assert features["observation.velocity"] == {
        "dtype": "float32",
        "shape": [2],
        "names": ["a", "b"],
    }
    rows = pq.read_table(tmp_path / "d" / "data" / "chunk-000" / "file-000.parquet").to_pydict()
    np.testing.assert_array_equal(np.array(rows["observation.velocity"]), np.concatenate(speeds))
    stats = json.loads((tmp_path / "d" / "meta" / "stats.json").read_text())
    assert stats["observation.velocity"]["max"] == [
        float(np.concatenate(speeds)[:, 0].max()),
        float(np.concatenate(speeds)[:, 1].max()),
    ]


def _ffmpeg_children() -> list[str]:
    """The ffmpeg processes (zombies too) whose parent is this process (Linux /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            name, fields = stat.read_text().split(" (", 1)[1].rsplit(") ", 1)
        except (OSError, ValueError):
            continue  # gone meanwhile
        if fields.split()[1] == str(os.getpid()) and "ffmpeg" in name:
            found.append(f"{stat.parent.name} {name} {fields.split()[0]}")
    return found


@pytest.mark.parametrize("case", BAD_INPUTS)
def test_a_bad_input_is_refused_in_one_line_leaving_nothing(tmp_path: Path, case: str) -> None:
    make, message = BAD_INPUTS[case]
    layout, episodes = make()
    folder = tmp_path / "dataset"
    with pytest.raises(OpenralError) as refused:
        write_dataset(folder, layout, iter(episodes))
    text = str(refused.value)
    assert "\n" not in text
    assert text.startswith(message), text
    assert list(tmp_path.iterdir()) == []  # neither the dataset nor its staging folder
    assert _ffmpeg_children() == []  # no encoder left running


def test_an_existing_folder_with_files_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "dataset"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep me")
    with pytest.raises(OpenralError, match=r"already exists; expected a new or empty folder$"):
        write_dataset(folder, LAYOUT, EPISODES)
    assert [p.name for p in folder.iterdir()] == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dataset"]


def test_a_failing_episode_source_leaves_nothing(tmp_path: Path) -> None:
    def stream() -> Iterator[DatasetEpisode]:
        yield EPISODES[0]
        raise RuntimeError("the simulator crashed")

    with pytest.raises(RuntimeError, match="the simulator crashed"):
        write_dataset(tmp_path / "dataset", LAYOUT, stream())
    assert list(tmp_path.iterdir()) == []


def test_missing_parent_folders_are_made(tmp_path: Path) -> None:
    folder = tmp_path / "nested" / "dataset"
    write_dataset(folder, LAYOUT, EPISODES[:1])
    assert [p.name for p in (tmp_path / "nested").iterdir()] == ["dataset"]
