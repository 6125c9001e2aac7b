"""Robot episodes as a LeRobot dataset v3.0 folder, written without torch or lerobot.

Every stream is one file (chunk 000, file 000) holding the episodes back to back:

- ``data/chunk-000/file-000.parquet``: a row per frame (``observation.state``, ``action``,
  ``next.success``, ``timestamp`` [s] = ``frame_index / fps``, ``frame_index`` from 0 each
  episode, ``episode_index``, the global ``index``, ``task_index``);
- ``videos/observation.images.<slot>/chunk-000/file-000.mp4``: a camera at ``fps`` (H.264,
  else MPEG-4 part 2);
- ``meta/episodes/chunk-000/file-000.parquet``: a row per episode (tasks, length, frame
  range, files, video span [s], ``stats/<feature>/<statistic>``); ``meta/tasks.parquet``,
  ``meta/stats.json`` (:mod:`openral_eval.lerobot_stats`) and ``meta/info.json``.

Episodes stream through, one's frames at a time (ffmpeg reads them from a pipe), into a
hidden sibling folder renamed into place once complete: nothing partial is left behind.
"""

from __future__ import annotations

import json
import math
import secrets
import shutil
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

import numpy as np
import numpy.typing as npt
import pyarrow as pa
import pyarrow.parquet as pq
from openral_core.errors import OpenralError

from openral_eval import lerobot_stats
from openral_eval.lerobot_video import VideoStream, video_codec

CODEBASE_VERSION: Final = "v3.0"
CHUNKS_SIZE: Final = 1000
DATA_FILE_MB: Final = 100  # LeRobot's file size targets [MB]; info.json states the larger of
VIDEO_FILE_MB: Final = 200  # each and of the file written (one file per stream here)
DATA_PATH: Final = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH: Final = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
_INDICES: Final = ("frame_index", "episode_index", "index", "task_index")


@dataclass(frozen=True)
class DatasetEpisode:
    """One episode of ``T`` frames."""

    task: str  # what the robot was asked to do, e.g. "lift the red cube"
    states: npt.NDArray[np.float32]  # (T, n_state) observation.state per frame
    actions: npt.NDArray[np.float32]  # (T, n_action) action per frame
    success: npt.NDArray[np.bool_]  # (T,) next.success per frame
    frames: Mapping[str, npt.NDArray[np.uint8]]  # slot -> (T, H, W, 3) RGB, H and W even
    extra: Mapping[str, npt.NDArray[np.float32]] = field(default_factory=dict)  # key -> (T, n)


@dataclass(frozen=True)
class DatasetLayout:
    """What every episode of a dataset holds."""

    fps: float  # frames per second [Hz] (the control rate)
    robot_type: str  # e.g. "franka_panda"
    state_names: tuple[str, ...]  # names of observation.state's entries
    action_names: tuple[str, ...]  # names of action's entries
    cameras: tuple[str, ...]  # slots; each is the feature "observation.images.<slot>"
    extra: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    """More float32 features of the frames (``observation.velocity`` …) and their names."""


@dataclass(frozen=True)
class DatasetSummary:
    """What :func:`write_dataset` wrote: episodes, frames and distinct tasks, and where."""

    folder: Path
    episodes: int
    frames: int
    tasks: int


def write_dataset(
    folder: Path, layout: DatasetLayout, episodes: Iterable[DatasetEpisode]
) -> DatasetSummary:
    """Write ``episodes`` (streamed) as a new LeRobot v3.0 dataset at ``folder``.

    Raises:
        OpenralError: ``folder`` exists and is not an empty folder, ``layout`` or an episode
            is malformed (lengths, widths, dtypes, non-finite values, camera slots or sizes),
            there is no episode, or ffmpeg fails; nothing is left at ``folder`` then.
    """
    _check_layout(layout)
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise OpenralError(f"{folder} already exists; expected a new or empty folder")
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = folder.parent / f".{folder.name}.partial-{secrets.token_hex(4)}"
    staging.mkdir()
    writer: _Writer | None = None
    try:
        writer = _Writer(staging, layout)
        for episode in episodes:
            writer.add(episode)
            del episode  # not held while the next one is made
        writer.finish()
        if folder.is_dir():
            folder.rmdir()
        staging.rename(folder)
    except BaseException:
        if writer is not None:
            writer.abort()
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return DatasetSummary(folder, len(writer.rows), writer.frames, len(writer.tasks))


def _check_layout(layout: DatasetLayout) -> None:
    if not (math.isfinite(layout.fps) and layout.fps > 0):
        raise OpenralError(f"layout.fps is {layout.fps}; expected a finite rate > 0 [Hz]")
    named = {"layout.state_names": layout.state_names, "layout.action_names": layout.action_names}
    for key, names in layout.extra.items():
        if not key.startswith("observation.") or key.startswith(
            ("observation.images.", "observation.state")
        ):
            raise OpenralError(
                f"layout.extra has {key!r}; expected observation.* keys other than state and images"
            )
        named[f"layout.extra[{key!r}]"] = names
    for where, names in named.items():
        if not names or len(set(names)) != len(names):
            raise OpenralError(f"{where} is {names!r}; expected distinct names, at least 1")
    slots = layout.cameras
    if len(set(slots)) != len(slots) or any(not s or "/" in s for s in slots):
        raise OpenralError(f"layout.cameras is {slots!r}; expected distinct slot names without /")


def _json_fps(fps: float) -> int | float:
    return int(fps) if float(fps).is_integer() else fps


def _episode_arrays(
    episode: DatasetEpisode, layout: DatasetLayout, index: int
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.bool_]]:
    """``episode``'s states, actions and success, checked against ``layout`` (see module)."""
    where = f"episode {index}"
    if not isinstance(episode.task, str) or not episode.task.strip():
        raise OpenralError(f"{where}: task is {episode.task!r}; expected a non-empty text")
    states, actions = np.asarray(episode.states), np.asarray(episode.actions)
    success = np.asarray(episode.success)
    length = states.shape[0] if states.ndim else 0
    if length < 1:
        raise OpenralError(f"{where}: states has shape {states.shape}; expected 1 row per frame")
    for name, array, shape, kinds in (
        ("states", states, (length, len(layout.state_names)), "fiu"),
        ("actions", actions, (length, len(layout.action_names)), "fiu"),
        ("success", success, (length,), "b"),
    ):
        if array.shape != shape:
            per = f", one column per layout.{name[:-1]}_names entry" if len(shape) > 1 else ""
            raise OpenralError(
                f"{where}: {name} has shape {array.shape}; expected {shape}: one row per frame{per}"
            )
        if array.dtype.kind not in kinds:
            wanted = "bool" if kinds == "b" else "real numbers"
            raise OpenralError(f"{where}: {name} has dtype {array.dtype}; expected {wanted}")
    for name, array in (("states", states), ("actions", actions)):
        bad = np.argwhere(~(np.abs(array.astype(np.float64)) <= np.finfo(np.float32).max))
        if len(bad):
            raise OpenralError(
                f"{where}: {name} has {len(bad)} non-finite value(s) (NaN, inf or beyond float32)"
                f", first at frame {bad[0][0]}, entry {bad[0][1]}; expected finite numbers"
            )
    return states.astype(np.float32), actions.astype(np.float32), success.astype(np.bool_)


def _episode_extra(
    episode: DatasetEpisode, layout: DatasetLayout, index: int, length: int
) -> dict[str, npt.NDArray[np.float32]]:
    """``episode``'s extra features, checked against ``layout.extra`` (keys, shapes, finite)."""
    where = f"episode {index}"
    if set(episode.extra) != set(layout.extra):
        raise OpenralError(
            f"{where}: extra has features {sorted(episode.extra)}; expected exactly "
            f"layout.extra {sorted(layout.extra)}"
        )
    out = {}
    for key, names in layout.extra.items():
        values = np.asarray(episode.extra[key])
        if values.shape != (length, len(names)) or values.dtype.kind not in "fiu":
            raise OpenralError(
                f"{where}: extra[{key!r}] is {values.dtype} {values.shape}; expected real "
                f"numbers of shape {(length, len(names))}"
            )
        if not np.all(np.abs(values.astype(np.float64)) <= np.finfo(np.float32).max):
            raise OpenralError(f"{where}: extra[{key!r}] has non-finite values; expected finite")
        out[key] = values.astype(np.float32)
    return out


def _episode_frames(
    episode: DatasetEpisode, layout: DatasetLayout, index: int, sizes: dict[str, tuple[int, int]]
) -> dict[str, npt.NDArray[np.uint8]]:
    """``episode``'s camera frames by feature key, checked (their sizes noted in ``sizes``)."""
    where, length = f"episode {index}", len(episode.success)
    if set(episode.frames) != set(layout.cameras):
        raise OpenralError(
            f"{where}: frames has camera slots {sorted(episode.frames)}; "
            f"expected exactly layout.cameras {sorted(layout.cameras)}"
        )
    frames = {f"observation.images.{s}": np.asarray(episode.frames[s]) for s in layout.cameras}
    for key, images in frames.items():
        shape, (height, width) = images.shape, sizes.get(key, ("H", "W"))
        fits = images.ndim == 4 and shape[0] == length and shape[3] == 3
        size = (shape[1], shape[2]) if fits else (0, 0)
        fits = fits and min(size) > 0 and not (size[0] % 2 or size[1] % 2)
        if not fits or sizes.setdefault(key, size) != size or images.dtype != np.uint8:
            slot = key.removeprefix("observation.images.")
            raise OpenralError(
                f"{where}: frames[{slot!r}] is {images.dtype} {shape}; "
                f"expected ({length}, {height}, {width}, 3) uint8 with H and W even"
            )
    return frames


def _vectors(layout: DatasetLayout) -> dict[str, tuple[str, ...]]:
    return {"observation.state": layout.state_names, **layout.extra, "action": layout.action_names}


def _data_schema(layout: DatasetLayout) -> pa.Schema:
    """The frame table's columns, in info.json's feature order."""
    fields = [(key, pa.list_(pa.float32(), len(names))) for key, names in _vectors(layout).items()]
    fields += [("next.success", pa.bool_()), ("timestamp", pa.float32())]
    return pa.schema(fields + [(name, pa.int64()) for name in _INDICES])


def _features(layout: DatasetLayout, sizes: Mapping[str, tuple[int, int]]) -> dict[str, object]:
    """info.json's ``features``: each feature's dtype, shape and names."""
    features: dict[str, object] = {
        key: {"dtype": "float32", "shape": [len(names)], "names": list(names)}
        for key, names in _vectors(layout).items()
    }
    features["next.success"] = {"dtype": "bool", "shape": [1], "names": None}
    for key, (height, width) in sizes.items():
        video = {"video.height": height, "video.width": width, "video.codec": video_codec()[0]}
        video |= {"video.pix_fmt": "yuv420p", "video.is_depth_map": False}
        video |= {"video.fps": _json_fps(layout.fps), "video.channels": 3, "has_audio": False}
        features[key] = {
            "dtype": "video",
            "shape": [height, width, 3],
            "names": ["height", "width", "channels"],
            "info": video,
        }
    for name, dtype in (("timestamp", "float32"), *((name, "int64") for name in _INDICES)):
        features[name] = {"dtype": dtype, "shape": [1], "names": None}
    return features


class _Writer:
    """The files of one dataset being written (see the module doc)."""

    def __init__(self, root: Path, layout: DatasetLayout) -> None:
        self.root, self.layout, self.frames = root, layout, 0
        self.rows: list[dict[str, object]] = []
        self.tasks: dict[str, int] = {}
        self.sizes: dict[str, tuple[int, int]] = {}
        self.videos: dict[str, VideoStream] = {}
        self.stats: dict[str, lerobot_stats.FeatureStats] = {}
        self.schema = _data_schema(layout)
        data = root / DATA_PATH.format(chunk_index=0, file_index=0)
        data.parent.mkdir(parents=True)
        self.data = pq.ParquetWriter(data, self.schema, compression="snappy")

    def add(self, episode: DatasetEpisode) -> None:
        """Append ``episode`` to the data file and the videos; note its row and stats."""
        index, start = len(self.rows), self.frames
        states, actions, success = _episode_arrays(episode, self.layout, index)
        frames, length = _episode_frames(episode, self.layout, index, self.sizes), len(states)
        task_index = self.tasks.setdefault(episode.task, len(self.tasks))
        steps = np.arange(length, dtype=np.int64)
        columns: dict[str, npt.NDArray[np.generic]] = {
            "observation.state": states,
            **_episode_extra(episode, self.layout, index, length),
            "action": actions,
            "next.success": success,
            "timestamp": (steps / self.layout.fps).astype(np.float32),
            "frame_index": steps,
            "episode_index": np.full(length, index, dtype=np.int64),
            "index": start + steps,
            "task_index": np.full(length, task_index, dtype=np.int64),
        }
        arrays = [
            pa.FixedSizeListArray.from_arrays(pa.array(v.ravel()), v.shape[1]) if v.ndim == 2 else v
            for v in columns.values()
        ]
        self.data.write_table(pa.Table.from_arrays(arrays, schema=self.schema))
        row: dict[str, object] = {"episode_index": index, "tasks": [episode.task]}
        row |= {"length": length, "data/chunk_index": 0, "data/file_index": 0}
        row |= {"dataset_from_index": start, "dataset_to_index": start + length}
        for key, images in frames.items():
            row |= self._encode(key, images)
        stats = lerobot_stats.episode_stats(columns, frames)
        row |= lerobot_stats.stats_columns(stats)
        row |= {"meta/episodes/chunk_index": 0, "meta/episodes/file_index": 0}
        self.stats = lerobot_stats.merge_dataset_stats(self.stats, stats)
        self.rows.append(row)
        self.frames += length

    def _encode(self, key: str, images: npt.NDArray[np.uint8]) -> dict[str, object]:
        """Append a camera's frames to its MP4; the episode's video columns (times in s)."""
        if key not in self.videos:
            path = self.root / VIDEO_PATH.format(video_key=key, chunk_index=0, file_index=0)
            self.videos[key] = VideoStream(path, self.sizes[key], self.layout.fps)
        stream = self.videos[key]
        start = stream.frames / self.layout.fps
        stream.write(images)
        end = stream.frames / self.layout.fps
        columns = {"chunk_index": 0, "file_index": 0, "from_timestamp": start, "to_timestamp": end}
        return {f"videos/{key}/{name}": value for name, value in columns.items()}

    def finish(self) -> None:
        """Close the data and video files; write the meta files."""
        if not self.rows:
            raise OpenralError("no episodes to write; expected at least one DatasetEpisode")
        self.data.close()
        for stream in self.videos.values():
            stream.close()
        meta = self.root / "meta"
        episodes = meta / "episodes/chunk-000/file-000.parquet"
        episodes.parent.mkdir(parents=True)
        pq.write_table(pa.Table.from_pylist(self.rows), episodes)
        pq.write_table(_tasks_table(self.tasks), meta / "tasks.parquet")
        (meta / "stats.json").write_text(json.dumps(lerobot_stats.stats_json(self.stats), indent=4))
        (meta / "info.json").write_text(json.dumps(self._info(), indent=4))

    def _info(self) -> dict[str, object]:
        """info.json's content."""
        return {
            "codebase_version": CODEBASE_VERSION,
            "robot_type": self.layout.robot_type,
            "total_episodes": len(self.rows),
            "total_frames": self.frames,
            "total_tasks": len(self.tasks),
            "chunks_size": CHUNKS_SIZE,
            "data_files_size_in_mb": max(DATA_FILE_MB, _biggest_mb(self.root / "data")),
            "video_files_size_in_mb": max(VIDEO_FILE_MB, _biggest_mb(self.root / "videos")),
            "fps": _json_fps(self.layout.fps),
            "splits": {"train": f"0:{len(self.rows)}"},
            "data_path": DATA_PATH,
            "video_path": VIDEO_PATH if self.layout.cameras else None,
            "features": _features(self.layout, self.sizes),
        }

    def abort(self) -> None:
        """Stop the encoders and close the data file, after a failure."""
        for stream in self.videos.values():
            stream.close(finish=False)
        self.data.close()  # idempotent


def _biggest_mb(folder: Path) -> int:
    """The size of the biggest file under ``folder`` [MB, rounded up]."""
    sizes = [path.stat().st_size for path in folder.rglob("*") if path.is_file()]
    return math.ceil(max(sizes, default=0) / 2**20)


def _tasks_table(tasks: Mapping[str, int]) -> pa.Table:
    """``meta/tasks.parquet``: ``task_index`` by task text, which pandas reads as its index
    ``task`` (pandas' schema note, as ``DataFrame.to_parquet`` writes it)."""
    kinds = {"task_index": ("int64", "int64"), "task": ("unicode", "object")}
    columns = [
        {"name": n, "field_name": n, "pandas_type": k, "numpy_type": t, "metadata": None}
        for n, (k, t) in kinds.items()
    ]
    note = {"index_columns": ["task"], "column_indexes": [], "columns": columns}
    table = pa.table({"task_index": list(tasks.values()), "task": list(tasks)})
    return table.replace_schema_metadata({"pandas": json.dumps(note)})
